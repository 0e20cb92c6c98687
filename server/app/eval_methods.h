// `haarcast eval`'s ranking of the per-pixel methods (issue 22, "Done
// when"): `fused`, `haar`, `splitsum`, `table` and `matrix` on one sphere
// under a real probe, for a rough, a glossy and a near-mirror material,
// each method at the product's defaults (what `render` draws):
//
//   speed    the CPU backend's frame time: the median of a few frames after
//            a warm-up frame, every method on the same machine one after
//            another (a ratio between methods, not an absolute figure);
//   storage  the BRDF data a method keeps per material (loadtest_storage.h
//            methodStoredBytes, loadtest's definition);
//   truth    truth PSNR, relative L2 and brightness (truth_metrics.h)
//            against the Monte Carlo reference converged to a tolerance
//            (seed 1), beside its floor: a second seed with the same
//            sample count against the first.
//
// Each criterion ranks the methods 1 (best: fastest, smallest, closest by
// relative L2) to 5; report.md shows the ranks, the figures behind them
// and each material's table. `eval --methods-only` runs this section alone;
// --quick runs it at 16², level 4.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "eval_truth.h"
#include "haarcast/core/rotation.h"

namespace haarcast::app {

// The methods ranked, in the report's order.
inline constexpr RotationMethod kRankedMethods[] = {RotationMethod::Fused, RotationMethod::Haar, RotationMethod::Splitsum,
                                                    RotationMethod::Table, RotationMethod::Matrix};

struct RankedMaterial {
  std::string role;  // "rough", "glossy", "near-mirror"
  std::string spec;  // render::materialFromSpec
};
// ggx:0.3 (rough), ggx:0.1 (glossy), ggx:0.02 (near-mirror): analytic, so
// that the reference converges (the MERL tables' few very bright cells do
// not, docs/evaluation.md "Sharp materials").
std::vector<RankedMaterial> rankedMaterials();

// 1 for the smallest value, ties sharing the smaller rank: {3, 1, 3} → {2, 1, 2}.
std::vector<int> ranksAscending(const std::vector<double>& values);

// 1,536 → "1.5 KiB" (binary units, one decimal; bytes whole).
std::string bytesText(double bytes);

// report["methods_ranked"]: config, and per material its truth, floor and
// every method's figures and ranks; "summary" the mean ranks per method.
// The probe: adams_place_bridge_1k.hdr from the data folder (the sharp
// materials' probe, docs/evaluation.md), else Grace, else the built-in sky
// (said in `notes`); --quick takes Grace or the sky.
nlohmann::json runMethodRanking(const TruthRun& run, std::vector<std::string>& notes);

// report.md's section "Methods ranked: speed, storage, truth"
// (eval_methods_report.cpp, with the two above: no scene needed).
std::string methodRankingMarkdown(const nlohmann::json& ranked);

}  // namespace haarcast::app
