// haarcast — the command line. One binary, one subcommand per job.
#include <cstdio>
#include <exception>
#include <iostream>

#include <CLI/CLI.hpp>

#include "bench_frame_command.h"
#include "eval.h"
#include "progress.h"
#include "reference_command.h"
#include "render_command.h"
#include "rotation_report.h"
#include "serve_command.h"

namespace {

int runReport(const haarcast::app::RotationReportOptions& options, bool json) {
  haarcast::app::StderrProgress progress;
  const auto report = haarcast::app::runRotationReport(
      options, [&progress](const std::string& line) { progress.message("[rotation-report] " + line); },
      progress.callback());
  if (json) {
    std::cout << haarcast::app::toJson(report).dump(2) << '\n';
  } else {
    std::cout << haarcast::app::toText(report);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"haarcast: all-frequency relighting by run-time rotation in the Haar domain"};
  app.require_subcommand(1);

  haarcast::app::RotationReportOptions report;
  bool json = false;
  std::string variant = "refined";
  auto* rr = app.add_subcommand("rotation-report", "Accuracy, speed and storage of every rotation method");
  rr->add_option("--level", report.level, "Map level n (M = 2^n), 2..7")->capture_default_str();
  rr->add_option("--rotations", report.rotations, "Random rotations per lobe")->capture_default_str();
  rr->add_option("--seed", report.seed, "Seed of the random rotations")->capture_default_str();
  rr->add_option("--haar-variant", variant, "Variant of `haar` scored as the method: faithful|local|refined")
      ->capture_default_str();
  rr->add_option("--haar-start-level", report.rotator.haarStartLevel, "Detail level `haar` starts from (-1 = finest)")
      ->capture_default_str();
  rr->add_option("--matrix-elevations", report.rotator.matrixElevations, "Elevations sampled by `matrix`")
      ->capture_default_str();
  rr->add_flag("--json", json, "Print JSON instead of a table");

  const auto runRender = haarcast::app::addRenderCommand(app);
  const auto runReference = haarcast::app::addReferenceCommand(app);
  const auto runEval = haarcast::app::addEvalCommand(app);
  const auto runBenchFrame = haarcast::app::addBenchFrameCommand(app);
  const auto runServe = haarcast::app::addServeCommand(app);

  try {
    app.parse(argc, argv);
    if (const int rc = runRender(); rc >= 0) return rc;
    if (const int rc = runReference(); rc >= 0) return rc;
    if (const int rc = runEval(); rc >= 0) return rc;
    if (const int rc = runBenchFrame(); rc >= 0) return rc;
    if (const int rc = runServe(); rc >= 0) return rc;
    if (rr->parsed()) {
      const auto v = haarcast::parseHaarVariant(variant);
      if (!v) throw std::invalid_argument("--haar-variant must be faithful, local or refined (got \"" + variant + "\")");
      report.rotator.haarVariant = *v;
      return runReport(report, json);
    }
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "haarcast: error: %s\n", e.what());
    return 2;
  }
  return 0;
}
