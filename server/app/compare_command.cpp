// `haarcast compare` (compare_command.h).
#include "compare_command.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <tuple>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "haarcast/core/light_split.h"
#include "haarcast/core/metrics.h"
#include "haarcast/io/image.h"
#include "truth_metrics.h"

namespace haarcast::app {
namespace {

struct CompareOptions {
  std::string reference;
  std::string test;
  std::string unoccluded;   // the reference without occlusion: marks shadowed pixels
  double shadowThreshold = 0.02;
  std::string errorImage;   // a PNG of the signed error, when set
  double errorScale = 0.2;  // the relative error drawn at full colour
};

double luminanceAt(const io::RgbImage& image, std::size_t pixel) {
  return luminance709(image.rgb[3 * pixel], image.rgb[3 * pixel + 1], image.rgb[3 * pixel + 2]);
}

// The channels of the pixels `keep` selects, as one signal.
std::vector<double> gather(const io::RgbImage& image, const std::vector<bool>& keep) {
  std::vector<double> out;
  for (std::size_t p = 0; p < keep.size(); ++p)
    if (keep[p])
      for (std::size_t c = 0; c < 3; ++c) out.push_back(image.rgb[3 * p + c]);
  return out;
}

void printRow(const char* name, std::size_t pixels, std::size_t total, const ErrorStats& e, double errorShare) {
  std::printf("| %s | %zu (%.1f %%) | %.2f | %.3g | %.2f %% | %.4f | %.1f %% |\n", name, pixels,
              100.0 * static_cast<double>(pixels) / static_cast<double>(std::max<std::size_t>(total, 1)), e.psnr, e.mse,
              100.0 * e.relativeL2, e.brightnessRatio, 100.0 * errorShare);
}

// Where a render errs: each object pixel's luminance error as a fraction of
// the reference's mean object luminance (so the picture weighs pixels as
// relative L2 does: a dark pixel's large relative error shows faint), red
// where the render is too bright and blue where too dark, at full colour
// from ±scale on; under it, a dim grey of the reference so that the shapes
// stay readable. Other pixels black.
void writeErrorImage(const std::string& path, const io::RgbImage& reference, const io::RgbImage& test,
                     const std::vector<bool>& object, double scale) {
  const std::size_t pixels = object.size();
  double peak = 0.0, sum = 0.0, count = 0.0;
  for (std::size_t p = 0; p < pixels; ++p) {
    peak = std::max(peak, luminanceAt(reference, p));
    if (object[p]) sum += luminanceAt(reference, p), count += 1.0;
  }
  const double mean = std::max(sum / std::max(count, 1.0), 1e-30);
  std::vector<std::uint8_t> rgba(4 * pixels, 0);
  for (std::size_t p = 0; p < pixels; ++p) {
    rgba[4 * p + 3] = 255;
    if (!object[p]) continue;
    const double r = luminanceAt(reference, p);
    const double e = std::clamp((luminanceAt(test, p) - r) / mean / scale, -1.0, 1.0);
    const double grey = 60.0 * std::sqrt(r / std::max(peak, 1e-30));
    const double strong = grey + (255.0 - grey) * std::abs(e);
    const double weak = grey * (1.0 - std::abs(e));
    rgba[4 * p + 0] = static_cast<std::uint8_t>(std::lround(e > 0 ? strong : weak));
    rgba[4 * p + 1] = static_cast<std::uint8_t>(std::lround(weak));
    rgba[4 * p + 2] = static_cast<std::uint8_t>(std::lround(e < 0 ? strong : weak));
  }
  io::writePngRgba8(path, rgba, reference.width, reference.height);
  std::printf("wrote %s: red = render too bright, blue = too dark, full colour at ±%.0f %% of the reference's mean\n",
              path.c_str(), 100.0 * scale);
}

int run(const CompareOptions& o) {
  const io::RgbImage reference = io::readImage(o.reference);
  const io::RgbImage test = io::readImage(o.test);
  if (reference.width != test.width || reference.height != test.height) {
    throw std::invalid_argument("compare: " + o.reference + " is " + std::to_string(reference.width) + "×" +
                                std::to_string(reference.height) + ", " + o.test + " is " + std::to_string(test.width) +
                                "×" + std::to_string(test.height));
  }
  const std::size_t pixels = static_cast<std::size_t>(reference.width) * static_cast<std::size_t>(reference.height);
  // The object pixels: wherever either image is not black (renders for
  // comparison use a black background).
  std::vector<bool> object(pixels, false);
  std::size_t covered = 0;
  for (std::size_t p = 0; p < pixels; ++p) {
    for (std::size_t c = 0; c < 3; ++c) object[p] = object[p] || reference.rgb[3 * p + c] != 0.0f || test.rgb[3 * p + c] != 0.0f;
    covered += object[p] ? 1 : 0;
  }
  if (covered == 0) throw std::invalid_argument("compare: both images are black");
  const ErrorStats all = compareSignals(std::span<const double>(gather(reference, object)), gather(test, object));
  std::printf("| pixels | count | PSNR (dB) | MSE | relative L2 | brightness | share of squared error |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  printRow("all", covered, covered, all, 1.0);
  if (!o.unoccluded.empty()) {
    const io::RgbImage open = io::readImage(o.unoccluded);
    if (open.width != reference.width || open.height != reference.height) {
      throw std::invalid_argument("compare: " + o.unoccluded + " is not the size of " + o.reference);
    }
    // Shadowed: the truth darker than the truth without occlusion by more
    // than the threshold (a fraction of its luminance).
    std::vector<bool> shadowed(pixels, false), lit(pixels, false);
    std::size_t nShadowed = 0, nLit = 0;
    for (std::size_t p = 0; p < pixels; ++p) {
      if (!object[p]) continue;
      const bool s = luminanceAt(reference, p) < (1.0 - o.shadowThreshold) * luminanceAt(open, p);
      (s ? shadowed : lit)[p] = true;
      (s ? nShadowed : nLit) += 1;
    }
    const double totalSquared = all.mse * static_cast<double>(3 * covered);
    for (const auto& [name, keep, count] : {std::tuple{"shadowed", &shadowed, nShadowed}, std::tuple{"lit", &lit, nLit}}) {
      if (count == 0) continue;
      const ErrorStats e = compareSignals(std::span<const double>(gather(reference, *keep)), gather(test, *keep));
      printRow(name, count, covered, e, totalSquared > 0.0 ? e.mse * static_cast<double>(3 * count) / totalSquared : 0.0);
    }
    std::vector<std::uint8_t> mask(pixels, 0);
    for (std::size_t p = 0; p < pixels; ++p) mask[p] = object[p] ? 1 : 0;
    const DarkPixels d = darkPixels(reference.rgb, open.rgb, test.rgb, mask);
    std::printf("\ndark: %zu of the %zu pixels whose reference keeps more than %.0f %% of its unoccluded light are over %.0f %% "
                "darker than the reference",
                d.dark, d.eligible, 100.0 * kDarkKeptShare, 100.0 * kDarkDrop);
    if (d.eligible > 0) {
      std::printf("; the darkest, test/reference %.3f, at x %zu, y %zu", d.worstRatio,
                  d.worstPixel % static_cast<std::size_t>(reference.width), d.worstPixel / static_cast<std::size_t>(reference.width));
    }
    std::printf("\n");
    // Where they are, when few enough to read.
    constexpr std::size_t kListed = 8;
    if (d.dark > 0 && d.dark <= kListed) {
      std::printf("dark pixels (x, y, test/reference):");
      for (std::size_t p : d.where)
        std::printf(" (%zu, %zu, %.3f)", p % static_cast<std::size_t>(reference.width),
                    p / static_cast<std::size_t>(reference.width), luminanceAt(test, p) / luminanceAt(reference, p));
      std::printf("\n");
    }
  }
  if (!o.errorImage.empty()) writeErrorImage(o.errorImage, reference, test, object, o.errorScale);
  return 0;
}

}  // namespace

std::function<int()> addCompareCommand(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  auto* c = app.add_subcommand("compare", "Error of a render against a reference: PSNR, relative L2, brightness, shadowed/lit split");
  c->add_option("reference", o->reference, "The reference image (EXR, HDR or PFM), e.g. from `haarcast reference --background black`")
      ->required();
  c->add_option("test", o->test, "The image to measure, the same size")->required();
  c->add_option("--unoccluded", o->unoccluded,
                "The reference rendered without occlusion (`reference --occlusion none`): splits the error into shadowed and lit pixels");
  c->add_option("--shadow-threshold", o->shadowThreshold, "A pixel is shadowed when the reference is darker than this fraction below the unoccluded one")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--error-image", o->errorImage,
                "Write a PNG of the per-pixel error (luminance, over the reference's mean): red where the test is brighter than the reference, blue where darker");
  c->add_option("--error-scale", o->errorScale, "The error, as a fraction of the reference's mean object luminance, that --error-image draws at full colour")
      ->capture_default_str()
      ->check(CLI::Range(1e-4, 10.0));
  return [c, o] { return c->parsed() ? run(*o) : -1; };
}

}  // namespace haarcast::app
