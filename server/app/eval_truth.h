// `haarcast eval`'s truth sections: renders against converged Monte Carlo
// references (cpu/reference.h), written into report.json and report.md.
//
//   truth          one glossy sphere (eval's first environment, its second
//                  table material), every rotation method at levels 5 and 6
//                  (7 for fused): how close the methods come where nothing
//                  shadows
//   shadow_truth   shadow-heavy scenes (shadowScenes), `fused` and `haar`
//                  at the product's defaults: truth PSNR, relative L2 and
//                  brightness, whole and split into shadowed and lit pixels
//                  (truth_metrics.h), beside the truth's own noise floor
//
// The truth of a shadow scene is the reference with every object occluding
// (seed 1, converged to the tolerance). Two more renders of the same sample
// count go with it: seed 2 (the floor: how far a second truth is from the
// first) and seed 1 with no occlusion at all, whose samples are the truth's
// own directions unoccluded, so that comparing the two marks the shadowed
// pixels (truth_metrics.h: 2 % darker in luminance).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "eval.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/cpu/reference.h"
#include "haarcast/render/scene.h"
#include "progress.h"

namespace haarcast::app {

struct TruthRun {
  const EvalOptions& options;
  render::RenderOptions base;  // cache folder, threads, black background; sizes and methods are set per render
  ProgressReporter& progress;
  std::function<void(const std::string&)> log;
};

// The Monte Carlo truth's options for eval's sections: a frame² render of
// the object pixels (black background), converged to `tolerance` within
// `maxSamples` per pixel on the run's threads; with `coarseQuickTables`,
// --quick samples from coarser tables (seconds, not tens).
render::ReferenceOptions truthReferenceOptions(const TruthRun& run, int frame, double tolerance, std::size_t maxSamples,
                                               bool coarseQuickTables);
// The Monte Carlo render, with eval's stage progress.
render::ReferenceResult monteCarlo(const TruthRun& run, const render::Scene& scene, const render::ReferenceOptions& ro,
                                   const std::string& stage);

// report["truth"]: `scene` (one object) against its Monte Carlo render, every
// method; `config` names what the scene is (model, environment, material).
nlohmann::json runMethodTruth(const TruthRun& run, const render::Scene& scene, nlohmann::json config);
std::string methodTruthMarkdown(const nlohmann::json& truth);

// The objects standing on a ground: a Lambert plane of half-size
// groundHalfSize at y = 0, subdivided into groundSubdivisions² quads (the
// renderer's per-vertex visibility needs vertices inside a shadow), as the
// scene's first object, then `objects` as posed. One place that makes the
// ground, so that it can become the scene's own ground later.
render::Scene groundedScene(const render::Environment& environment, std::vector<render::SceneObject> objects,
                            double groundHalfSize = 3.0, int groundSubdivisions = 64);

struct ShadowScene {
  std::string name;         // report key
  std::string description;  // report.md's line
  std::string environment;
  render::Scene scene;
};

// pillars-lambert, pillars-ggx (makePillars under the suns sky), grounded (a
// sphere and a torus on a ground under the suns) and, when the data folder
// has meshes/bunny.ply and a Grace probe, bunny-grace (Lambert). --quick: the
// first and the grounded one, coarser. `notes` gets what was left out.
std::vector<ShadowScene> shadowScenes(const EvalOptions& options, std::vector<std::string>& notes);

// report["shadow_truth"]: every shadow scene, its truth, floor and methods.
nlohmann::json runShadowTruth(const TruthRun& run, std::vector<std::string>& notes);
std::string shadowTruthMarkdown(const nlohmann::json& shadowTruth);

}  // namespace haarcast::app
