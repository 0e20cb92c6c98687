// `haarcast eval`: the seed's experiments, on whatever of its assets a data
// folder holds (built-in stand-ins otherwise), written as report.md and
// report.json with the figures beside them.
//
//   Tables 1–4   average seed PSNR (haar vs spatial renders, object pixels)
//                per environment, for two materials at two levels, over the
//                models and random object rotations — for haar's default
//                (refined) and the seed as written (faithful)
//   MSE plots    per model and environment (PNG)
//   glossiness   three materials × 4, 16, 64, 256 light coefficients (PNG)
//   truth        every rotation method against a converged Monte Carlo render
#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

namespace haarcast::app {

struct EvalOptions {
  std::string dataDir;  // ../shared/data layout: probes/, meshes/, brdfs/
  std::string outDir = "eval";
  bool quick = false;   // the small version the test suite runs
  bool truthOnly = false;  // only the truth section (Monte Carlo and every method)
  unsigned threads = 0;
};

// Runs everything and writes outDir/report.md, outDir/report.json and the
// PNGs; returns the JSON (keys "tables", "truth", "glossiness", "timings").
nlohmann::json runEval(const EvalOptions& options, const std::function<void(const std::string&)>& log);

std::function<int()> addEvalCommand(CLI::App& app);

}  // namespace haarcast::app
