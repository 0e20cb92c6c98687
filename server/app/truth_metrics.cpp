#include "truth_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace haarcast::app {
namespace {

void checkSizes(std::size_t rgb, std::size_t rgb2, std::size_t mask, std::size_t other, const char* what) {
  if (rgb != rgb2 || rgb != 3 * mask || (other != 0 && other != mask)) {
    throw std::invalid_argument(std::string(what) + ": images of " + std::to_string(rgb) + " and " +
                                std::to_string(rgb2) + " values for a mask of " + std::to_string(mask) + " pixels");
  }
}

struct Sums {
  std::size_t pixels = 0;
  double err2 = 0.0, ref2 = 0.0, ref = 0.0, got = 0.0;
};

}  // namespace

std::vector<std::uint8_t> shadowedPixels(std::span<const float> occluded, std::span<const float> unoccluded,
                                         std::span<const std::uint8_t> mask, double threshold) {
  checkSizes(occluded.size(), unoccluded.size(), mask.size(), 0, "shadowedPixels");
  std::vector<std::uint8_t> out(mask.size(), 0);
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (mask[i] && luminance(&occluded[3 * i]) < (1.0 - threshold) * luminance(&unoccluded[3 * i])) out[i] = 1;
  }
  return out;
}

TruthError compareWithTruth(std::span<const float> truth, std::span<const float> test,
                            std::span<const std::uint8_t> mask, std::span<const std::uint8_t> shadowed) {
  checkSizes(truth.size(), test.size(), mask.size(), shadowed.size(), "compareWithTruth");
  Sums groups[2];  // [0] lit, [1] shadowed
  double peak = 0.0;
  bool any = false;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    Sums& g = groups[!shadowed.empty() && shadowed[i] ? 1 : 0];
    ++g.pixels;
    for (std::size_t c = 0; c < 3; ++c) {
      const double r = truth[3 * i + c], a = test[3 * i + c];
      g.err2 += (a - r) * (a - r);
      g.ref2 += r * r;
      g.ref += r;
      g.got += a;
      peak = any ? std::max(peak, r) : r;
      any = true;
    }
  }
  if (!any) throw std::invalid_argument("compareWithTruth: the mask covers no pixel");
  Sums all;
  for (const Sums& g : groups) {
    all.pixels += g.pixels;
    all.err2 += g.err2;
    all.ref2 += g.ref2;
    all.ref += g.ref;
    all.got += g.got;
  }
  TruthError e;
  e.mse = all.err2 / (3.0 * static_cast<double>(all.pixels));
  e.psnr = e.mse == 0.0 ? 300.0 : std::min(300.0, 10.0 * std::log10(peak * peak / e.mse));
  e.relativeL2 = all.ref2 > 0.0 ? std::sqrt(all.err2 / all.ref2) : 0.0;
  e.brightness = all.ref > 0.0 ? all.got / all.ref : 0.0;
  auto group = [&](const Sums& g) {
    GroupError out;
    out.pixels = g.pixels;
    out.pixelFraction = static_cast<double>(g.pixels) / static_cast<double>(all.pixels);
    out.errorShare = all.err2 > 0.0 ? g.err2 / all.err2 : 0.0;
    out.relativeL2 = g.ref2 > 0.0 ? std::sqrt(g.err2 / g.ref2) : 0.0;
    out.brightness = g.ref > 0.0 ? g.got / g.ref : 0.0;
    return out;
  };
  e.lit = group(groups[0]);
  e.shadowed = group(groups[1]);
  return e;
}

nlohmann::json toJson(const TruthError& e) {
  auto group = [](const GroupError& g) {
    return nlohmann::json{{"pixels", g.pixels},          {"pixel_fraction", g.pixelFraction},
                          {"error_share", g.errorShare}, {"relative_l2", g.relativeL2},
                          {"brightness", g.brightness}};
  };
  return {{"psnr", e.psnr},           {"mse", e.mse},           {"relative_l2", e.relativeL2},
          {"brightness", e.brightness}, {"shadowed", group(e.shadowed)}, {"lit", group(e.lit)}};
}

DarkPixels darkPixels(std::span<const float> truth, std::span<const float> unoccluded, std::span<const float> test,
                      std::span<const std::uint8_t> mask, double keptShare, double darker) {
  checkSizes(truth.size(), unoccluded.size(), mask.size(), 0, "darkPixels");
  checkSizes(truth.size(), test.size(), mask.size(), 0, "darkPixels");
  DarkPixels out;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    const double r = luminance(&truth[3 * i]);
    if (!mask[i] || !(r > keptShare * luminance(&unoccluded[3 * i]))) continue;
    ++out.eligible;
    const double ratio = luminance(&test[3 * i]) / r;  // r > 0 here
    if (ratio < 1.0 - darker) {
      ++out.dark;
      out.where.push_back(i);
    }
    if (ratio < out.worstRatio) {
      out.worstRatio = ratio;
      out.worstPixel = i;
    }
  }
  return out;
}

nlohmann::json toJson(const DarkPixels& d) {
  return {{"eligible", d.eligible}, {"dark", d.dark}, {"worst_ratio", d.worstRatio}, {"worst_pixel", d.worstPixel}};
}

}  // namespace haarcast::app
