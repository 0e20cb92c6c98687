// haarcast — the command line. One binary, one subcommand per job.
#include <cstdio>
#include <exception>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench_frame_command.h"
#include "compare_command.h"
#include "haarcast/backends/backends.h"
#include "eval.h"
#include "haarcast/client/flag_suggest.h"
#include "loadtest_command.h"
#include "progress.h"
#include "reference_command.h"
#include "render_command.h"
#include "rotation_report.h"
#include "serve_command.h"

namespace {

// A first argument that is not an option and names no command: CLI11 would
// only say "A subcommand is required". Name the word, the nearest command
// and every command.
std::optional<std::string> unknownCommand(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return std::nullopt;
  const std::string word = argv[1];
  std::string all;
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    const std::string& name = sub->get_name();
    if (name == word) return std::nullopt;
    all += (all.empty() ? "" : ", ") + name;
    names.push_back(name);
  }
  std::string message = "unknown command \"" + word + "\"";
  if (const auto near = haarcast::cli::nearestName(word, names)) message += "; did you mean " + *near + "?";
  return message + " (commands: " + all + "; --help explains each)";
}

// CLI11 refused the arguments of `command` (named by argv[1]): the flags it
// does not know, each with the one most likely meant. Empty when none of the
// words is an unknown flag (CLI11's own message says what is wrong then).
std::vector<std::string> unknownFlagLines(CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return {};
  CLI::App* command = nullptr;
  for (CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (sub->get_name() == argv[1]) command = sub;
  }
  if (!command) return {};
  return haarcast::cli::unknownFlags(*command, std::vector<std::string>(argv + 2, argv + argc));
}

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
  app.footer(haarcast::backends::buildDescription());

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
  const auto runLoadtest = haarcast::app::addLoadtestCommand(app);
  const auto runCompare = haarcast::app::addCompareCommand(app);

  if (argc < 2) {
    // A bare `haarcast`: what it can do, not only that it needs a command.
    std::fprintf(stderr, "haarcast: a command is required. The commands:\n%s"
                         "`haarcast COMMAND --help` lists a command's flags.\n",
                 haarcast::cli::commandList(app).c_str());
    return 2;
  }
  if (const auto unknown = unknownCommand(app, argc, argv)) {
    std::fprintf(stderr, "haarcast: error: %s\n", unknown->c_str());
    return 2;
  }
  try {
    app.parse(argc, argv);
    if (const int rc = runRender(); rc >= 0) return rc;
    if (const int rc = runReference(); rc >= 0) return rc;
    if (const int rc = runEval(); rc >= 0) return rc;
    if (const int rc = runBenchFrame(); rc >= 0) return rc;
    if (const int rc = runServe(); rc >= 0) return rc;
    if (const int rc = runLoadtest(); rc >= 0) return rc;
    if (const int rc = runCompare(); rc >= 0) return rc;
    if (rr->parsed()) {
      const auto v = haarcast::parseHaarVariant(variant);
      if (!v) throw std::invalid_argument("--haar-variant must be faithful, local or refined (got \"" + variant + "\")");
      report.rotator.haarVariant = *v;
      return runReport(report, json);
    }
  } catch (const CLI::ExtrasError& e) {
    // A flag the command does not take: name it and the one meant.
    const auto lines = unknownFlagLines(app, argc, argv);
    if (lines.empty()) return app.exit(e) == 0 ? 0 : 2;
    for (const auto& line : lines) std::fprintf(stderr, "haarcast %s: error: %s\n", argv[1], line.c_str());
    std::fprintf(stderr, "`haarcast %s --help` lists its flags.\n", argv[1]);
    return 2;
  } catch (const CLI::ParseError& e) {
    // --help exits 0; every flag error exits 2, as the checks below do.
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "haarcast: error: %s\n", e.what());
    return 2;
  }
  return 0;
}
