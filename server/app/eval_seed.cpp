#include "eval_seed.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <stdexcept>

#include <glm/trigonometric.hpp>

#include "haarcast/core/rotation.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/io/image.h"
#include "haarcast/render/exposure_meter.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/tonemap.h"
#include "number_format.h"

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;

std::string levelKey(int level) { return "level" + std::to_string(level); }

// The figure names, recorded in report.json: the script draws to them and
// report.md links them, so both read them from one place.
std::string msePlotName(int level, const std::string& material) {
  return "mse_level" + std::to_string(level) + "_" + material + ".png";
}

// A square of the image: the object's bounding box (mask), grown by a
// margin and to at least minSize, kept inside the image where it fits.
struct Square {
  int x = 0, y = 0, size = 0;
};

Square squareAround(const std::vector<std::uint8_t>& mask, int width, int height, int minSize) {
  int x0 = width, y0 = height, x1 = -1, y1 = -1;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      if (mask[static_cast<std::size_t>(y * width + x)]) {
        x0 = std::min(x0, x), x1 = std::max(x1, x);
        y0 = std::min(y0, y), y1 = std::max(y1, y);
      }
  const int full = std::min(width, height);
  if (x1 < 0) return {0, 0, full};  // nothing covered: the whole frame
  const int margin = std::max(1, full / 32);
  const int size = std::min(full, std::max({x1 - x0 + 1 + 2 * margin, y1 - y0 + 1 + 2 * margin, minSize}));
  auto start = [&](int lo, int hi, int extent) {
    return std::clamp((lo + hi + 1 - size) / 2, 0, extent - size);  // centred on the box
  };
  return {start(x0, x1, width), start(y0, y1, height), size};
}

io::RgbImage cropped(const io::RgbImage& image, const Square& s) {
  io::RgbImage out = io::makeImage(s.size, s.size);
  for (int y = 0; y < s.size; ++y)
    for (int x = 0; x < s.size; ++x)
      for (int c = 0; c < 3; ++c) out.at(y, x, c) = image.at(s.y + y, s.x + x, c);
  return out;
}

}  // namespace

void runSeedTables(const SeedRun& run, const TableSizes& sizes, nlohmann::json& report) {
  const EvalAssets& a = run.assets;
  const StageProgress inner = run.progress.callback();  // the renders' own long stages (visibility)
  const std::vector<glm::dvec3> poses = [&] {
    std::vector<glm::dvec3> p;
    for (const EulerYXY& r : randomRotations(sizes.rotations * static_cast<int>(a.models.size()), 2026u)) {
      p.push_back(glm::degrees(glm::dvec3(r.beta, r.alpha, r.gamma)));
    }
    return p;
  }();
  const auto rotations = static_cast<std::size_t>(sizes.rotations);
  const std::string stage = "eval tables 1–4";
  const std::size_t renders =
      sizes.levels.size() * a.tableMaterials.size() * a.environments.size() * a.models.size() * rotations;
  std::size_t rendered = 0;
  run.progress.update(stage, 0, renders);
  for (int level : sizes.levels) {
    for (const auto& [matName, material] : a.tableMaterials) {
      for (const auto& [envName, env] : a.environments) {
        double sumRefined = 0.0, sumFaithful = 0.0;
        int count = 0;
        for (std::size_t mi = 0; mi < a.models.size(); ++mi) {
          double modelMseRefined = 0.0, modelMseFaithful = 0.0;
          for (std::size_t r = 0; r < rotations; ++r) {
            const render::Scene scene = singleObjectScene(env, a.models[mi].first, a.models[mi].second, material,
                                                          poses[mi * rotations + r]);
            render::RenderOptions opt = run.base;
            opt.width = opt.height = sizes.frame;
            opt.level = level;
            opt.method = RotationMethod::Spatial;
            const render::RenderResult spatial = render::renderCpu(scene, opt, inner);
            opt.method = RotationMethod::Haar;
            opt.rotator.haarVariant = HaarVariant::Refined;
            const ErrorStats refined = objectError(spatial, render::renderCpu(scene, opt, inner).image, spatial.objectMask);
            opt.rotator.haarVariant = HaarVariant::Faithful;
            const ErrorStats faithful = objectError(spatial, render::renderCpu(scene, opt, inner).image, spatial.objectMask);
            sumRefined += refined.psnr;
            sumFaithful += faithful.psnr;
            modelMseRefined += refined.mse / static_cast<double>(rotations);
            modelMseFaithful += faithful.mse / static_cast<double>(rotations);
            ++count;
            // The stage ends after its last result line, below.
            if (++rendered < renders) run.progress.update(stage, rendered, renders);
          }
          report["mse"][levelKey(level)][matName][envName][a.models[mi].first] = {
              {"refined", modelMseRefined}, {"faithful", modelMseFaithful}};
        }
        report["tables"][levelKey(level)][matName][envName] = {
            {"refined", sumRefined / count}, {"faithful", sumFaithful / count}};
        run.log("table level " + std::to_string(level) + " " + matName + " " + envName + ": refined " +
                fmt(sumRefined / count) + " dB, faithful " + fmt(sumFaithful / count) + " dB");
      }
      report["figures"]["mse"][levelKey(level)][matName] = msePlotName(level, matName);
    }
  }
  run.progress.update(stage, renders, renders);
}

// Each tile is a PNG of its own (glossiness/); the script lays them out with
// their labels. Every tile is cropped to the same square around the object
// (the union of the renders' object masks), so that the object, not the
// background, fills the sheet and the tiles still line up. `haar` renders
// them: it keeps the light's k largest coefficients (fused takes the light
// whole, so k would change nothing).
nlohmann::json runGlossiness(const SeedRun& run, const std::string& outDir, int level, int frame) {
  if (frame < kMinGlossTile) {
    throw std::invalid_argument("eval: glossiness frames of " + std::to_string(frame) + " px are under the " +
                                std::to_string(kMinGlossTile) + " px a tile needs");
  }
  const EvalAssets& a = run.assets;
  const StageProgress inner = run.progress.callback();
  const std::vector<std::size_t> ks = {4, 16, 64, 256};
  const std::string stage = "eval glossiness";
  const std::size_t renders = a.glossMaterials.size() * ks.size();
  std::size_t rendered = 0;
  run.progress.update(stage, 0, renders);
  fs::create_directories(fs::path(outDir) / "glossiness");
  std::vector<std::vector<io::RgbImage>> byMaterial;  // [material][k]
  std::vector<std::uint8_t> covered(static_cast<std::size_t>(frame * frame), 0);
  for (const auto& [matName, material] : a.glossMaterials) {
    byMaterial.emplace_back();
    for (std::size_t k : ks) {
      render::RenderOptions opt = run.base;
      opt.method = RotationMethod::Haar;
      opt.level = level;
      opt.width = opt.height = frame;
      opt.lightCoefficients = k;
      render::RenderResult r = render::renderCpu(
          singleObjectScene(a.environments.front().second, a.glossModelName, a.glossModel, material, {0.0, 20.0, 0.0}),
          opt, inner);
      for (std::size_t i = 0; i < covered.size(); ++i) covered[i] |= r.objectMask[i];
      byMaterial.back().push_back(std::move(r.image));
      run.progress.update(stage, ++rendered, renders);
    }
  }
  const Square crop = squareAround(covered, frame, frame, kMinGlossTile);
  nlohmann::json tiles = nlohmann::json::array();  // [row = k][column = material]
  for (std::size_t row = 0; row < ks.size(); ++row) tiles.push_back(nlohmann::json::array());
  for (std::size_t m = 0; m < a.glossMaterials.size(); ++m) {
    // One exposure per material, from its richest render, through the
    // display transform every haarcast image uses (render/tonemap.h).
    const double stops = render::meterExposure(byMaterial[m].back(), covered, {}, render::ToneCurve::Reinhard).stops;
    for (std::size_t row = 0; row < ks.size(); ++row) {
      const std::string file = "glossiness/k" + std::to_string(ks[row]) + "_" + a.glossMaterials[m].first + ".png";
      const io::RgbImage tile = cropped(byMaterial[m][row], crop);
      io::writePngRgba8((fs::path(outDir) / file).string(), render::tonemapRgba8(tile, stops), tile.width, tile.height);
      tiles[row].push_back(file);
    }
  }
  nlohmann::json g = {{"file", "glossiness.png"}, {"model", a.glossModelName}, {"level", level},
                      {"method", "haar"}, {"environment", a.environments.front().first},
                      {"light_coefficients", ks}, {"frame_size", frame}, {"tile_size", crop.size}, {"tiles", tiles}};
  for (const auto& [name, m] : a.glossMaterials) g["materials"].push_back(name);
  return g;
}

}  // namespace haarcast::app
