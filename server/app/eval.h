// `haarcast eval`: the seed's experiments, on whatever of its assets a data
// folder holds (built-in stand-ins otherwise), written as report.md and
// report.json with the figures beside them.
//
//   Tables 1–4   average seed PSNR (haar vs spatial renders, object pixels)
//                per environment, for two materials at levels 5 and 6, over
//                the models and random object rotations — for haar's default
//                (refined) and the seed as written (faithful) — beside the
//                paper's own figures (eval_seed.h, seed_tables.h)
//   MSE data     per model and environment
//   glossiness   three materials × 4, 16, 64, 256 light coefficients (one
//                PNG per tile in glossiness/, at least 128 px)
//   truth        every rotation method against a converged Monte Carlo render
//   shadow truth shadow-heavy scenes (objects shadowing themselves, each
//                other and a ground) against the reference with every object
//                occluding: whole, shadowed and lit pixels (eval_truth.h)
//   methods ranked  fused, haar, splitsum, table and matrix on speed, storage
//                and truth for a rough, a glossy and a near-mirror sphere
//                under a real probe (eval_methods.h)
//
// The figures (MSE plots, the labelled glossiness sheet) are drawn from
// report.json by tools/plot_report.py with matplotlib (report_figures.h);
// each names its frame size, level and machine (report.json's
// config.machine, machine_info.h). The reported times include them.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "progress.h"
#include "report_figures.h"

namespace haarcast::app {

struct EvalOptions {
  std::string dataDir;  // ../shared/data layout: probes/, meshes/, brdfs/
  std::string outDir = "eval";
  bool quick = false;   // every section, smaller: a few minutes on two cores
  // Tables 1–4: the models (kSeedModels' names; empty = the seed's five, or
  // --quick's four without the bunny), square frame size and random
  // rotations per model (0 = 24 and 1 with --quick, else 48 and 2).
  std::vector<std::string> models;
  int tablesFrame = 0;
  int tablesRotations = 0;
  // Glossiness: frame size (at least kMinGlossTile) and map level (0 = 144
  // and 5 with --quick, else 256 and 6).
  int glossFrame = 0;
  int glossLevel = 0;
  bool seedOnly = false;   // only the seed's sections (Tables 1–4, MSE data, glossiness: the ones with figures)
  bool truthOnly = false;  // only the truth sections (Monte Carlo and every method, shadow scenes)
  bool shadowsOnly = false;  // only the shadow truth (implies truthOnly)
  int truthFrame = 0;      // shadow truth frame size; 0 = 16 (quick) or 64
  bool methodsOnly = false;  // only the ranking of the methods (eval_methods.h)
  int methodsFrame = 0;      // its frame size; 0 = 16 (quick) or 64
  int methodsLevel = 0;      // its map level; 0 = 4 (quick) or 5
  bool figures = true;     // run tools/plot_report.py on report.json
  unsigned threads = 0;
};

struct EvalResult {
  nlohmann::json report;  // keys "config", "tables", "seed_tables", "mse", "figures", "glossiness", "truth",
                          // "shadow_truth", "methods_ranked", "timings"
  FigureRun figures;      // whether the figures were drawn, and why not
};

// Runs everything and writes outDir/report.json, the figures from it (when
// python3 has matplotlib) and outDir/report.md. Stages and result lines go
// to `progress`.
EvalResult runEval(const EvalOptions& options, ProgressReporter& progress);

std::function<int()> addEvalCommand(CLI::App& app);

}  // namespace haarcast::app
