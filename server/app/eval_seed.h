// The seed's own experiments as `haarcast eval` renders them:
//
//   Tables 1–4   average seed PSNR (haar vs spatial renders, object pixels)
//                per environment, for two materials at levels 5 and 6, over
//                the models and random object rotations — for haar's default
//                (refined) and the seed as written (faithful); the MSE of
//                each model beside (the seed's MSE figures)
//   glossiness   three materials × 4, 16, 64, 256 light coefficients kept
//                by `haar` (the seed's glossiness figure), one PNG per tile
//
// The paper's numbers and the comparison with ours are seed_tables.h's.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "eval_assets.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "progress.h"

namespace haarcast::app {

struct SeedRun {
  const EvalAssets& assets;
  render::RenderOptions base;  // cache folder, threads, black background, every light coefficient
  ProgressReporter& progress;
  std::function<void(const std::string&)> log;
};

struct TableSizes {
  std::vector<int> levels;
  int frame = 0;      // square frames, pixels
  int rotations = 0;  // random rotations per model
};

// Fills report["tables"] (level → material → environment → mean PSNR per
// variant), report["mse"] (… → model → mean MSE per variant) and
// report["figures"]["mse"] (level → material → the plot's file name).
void runSeedTables(const SeedRun& run, const TableSizes& sizes, nlohmann::json& report);

// The smallest tile the glossiness grid writes: smaller ones were too
// blocky to show a highlight's shape.
inline constexpr int kMinGlossTile = 128;

// report["glossiness"]: the tiles written under outDir/glossiness/, each a
// square crop around the object of a frame×frame render, at least
// kMinGlossTile pixels (frame must be at least that).
nlohmann::json runGlossiness(const SeedRun& run, const std::string& outDir, int level, int frame);

}  // namespace haarcast::app
