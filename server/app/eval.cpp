#include "eval.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "eval_assets.h"
#include "eval_methods.h"
#include "eval_seed.h"
#include "eval_truth.h"
#include "machine_info.h"
#include "number_format.h"
#include "progress.h"
#include "report_figures.h"
#include "seed_tables.h"

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// ["a", "b", 4] → "a, b, 4": lists in report.md's prose.
std::string listed(const nlohmann::json& array) {
  std::string out;
  for (const auto& v : array) out += (out.empty() ? "" : ", ") + (v.is_string() ? v.get<std::string>() : v.dump());
  return out;
}

// report.md's timings: one row per stage of report.json's "timings".
std::string timingsTable(const nlohmann::json& timings) {
  const std::vector<std::pair<const char*, const char*>> rows = {
      {"tables_s", "Tables 1–4 and the MSE data"},
      {"glossiness_s", "glossiness grid"},
      {"truth_s", "truth PSNR (Monte Carlo and every method)"},
      {"shadow_truth_s", "shadow truth (three Monte Carlo renders per scene, fused and haar)"},
      {"methods_ranked_s", "methods ranked (two Monte Carlo renders per material, five methods)"},
      {"figures_s", "figures (tools/plot_report.py, matplotlib)"}};
  const double total = timings.value("total_s", 0.0);
  std::ostringstream md;
  auto row = [&](const std::string& name, double s) {
    md << "| " << name << " | " << fmt(s, 1) << " | " << formatDuration(s) << " | "
       << (total > 0.0 ? fmt(100.0 * s / total, 0) + " %" : std::string()) << " |\n";
  };
  md << "| stage | seconds | time | share |\n|---|---:|---:|---:|\n";
  double stages = 0.0;
  for (const auto& [key, name] : rows) {
    if (!timings.contains(key)) continue;
    row(name, timings[key].get<double>());
    stages += timings[key].get<double>();
  }
  row("loading the assets, writing the reports", std::max(0.0, total - stages));
  md << "| **total** | " << fmt(total, 1) << " | " << formatDuration(total) << " | |\n";
  return md.str();
}

// The sizes a run uses: the options where set, else --quick's or the full
// run's. --quick keeps every table of the seed (levels 5 and 6, every probe)
// with fewer models, rotations and pixels, so that it runs in a few minutes
// on two cores; the full run fits 30 minutes there.
EvalOptions withDefaults(EvalOptions o) {
  const auto orDefault = [&](int& v, int quick, int full) {
    if (v <= 0) v = o.quick ? quick : full;
  };
  orDefault(o.tablesFrame, 24, 48);
  orDefault(o.tablesRotations, 1, 2);
  orDefault(o.glossFrame, 144, 256);
  orDefault(o.glossLevel, 5, 6);
  if (o.models.empty() && o.quick) o.models = {"sphere", "easter", "venus", "cat"};  // the bunny's visibility costs a minute
  return o;
}

}  // namespace

EvalResult runEval(const EvalOptions& options, ProgressReporter& progress) {
  const EvalOptions o = withDefaults(options);
  if (int(o.seedOnly) + int(o.methodsOnly) + int(o.truthOnly || o.shadowsOnly) > 1) {
    throw std::invalid_argument(
        "eval: --seed-only, --methods-only and --truth-only (or --shadows-only) each run a part; choose one");
  }
  const bool truthOnly = o.truthOnly || o.shadowsOnly;
  // The sections: the seed's (tables, glossiness), the truth, the shadows,
  // the ranking of the methods; each flag keeps some of them.
  const bool seedSections = !truthOnly && !o.methodsOnly;
  const bool truthSection = !o.shadowsOnly && !o.methodsOnly && !o.seedOnly;
  const bool shadowSection = !o.methodsOnly && !o.seedOnly;
  const bool rankingSection = !o.shadowsOnly && !o.seedOnly;
  const auto tStart = Clock::now();
  fs::create_directories(o.outDir);
  auto log = [&](const std::string& line) { progress.message("[eval] " + line); };
  const EvalAssets a = discoverAssets(o);
  for (const auto& n : a.notes) log("note: " + n);

  const TableSizes tableSizes{{5, 6}, o.tablesFrame, o.tablesRotations};  // the seed's Tables 1–4 levels
  render::RenderOptions base;
  base.width = base.height = o.tablesFrame;
  base.lightCoefficients = 1u << 20;  // all: the tables isolate rotation error
  base.environmentBackground = false;
  base.visibility.supersampling = 1;
  base.cacheDir = (fs::path(o.outDir) / "cache").string();
  base.threads = o.threads;

  nlohmann::json report;
  report["config"] = {{"quick", o.quick}, {"frame", o.tablesFrame}, {"rotations_per_model", o.tablesRotations},
                      {"levels", tableSizes.levels}, {"machine", toJson(machineInfo())}};
  for (const auto& [name, env] : a.environments) report["config"]["environments"].push_back(name);
  for (const auto& [name, m] : a.models) report["config"]["models"].push_back(name);
  for (const auto& [name, m] : a.tableMaterials) report["config"]["table_materials"].push_back(name);
  report["notes"] = a.notes;

  // ---- the seed's experiments: Tables 1–4, the MSE data, glossiness --------
  const SeedRun seedRun{a, base, progress, log};
  if (seedSections) {
    const auto tTables = Clock::now();
    runSeedTables(seedRun, tableSizes, report);
    report["seed_tables"] = seedTableComparison(report["tables"], report["config"]);
    report["timings"]["tables_s"] = since(tTables);
    const auto tGloss = Clock::now();
    report["glossiness"] = runGlossiness(seedRun, o.outDir, o.glossLevel, o.glossFrame);
    report["timings"]["glossiness_s"] = since(tGloss);
  }

  // ---- Truth: the methods against converged Monte Carlo renders -------------
  const TruthRun truthRun{o, base, progress, log};
  const auto tTruth = Clock::now();
  if (truthSection) {
    const auto& model = a.models.front();
    const render::Scene scene = singleObjectScene(a.environments.front().second, model.first, model.second,
                                                  a.tableMaterials.back().second, {0.0, 20.0, 0.0});
    report["truth"] = runMethodTruth(truthRun, scene,
                                     {{"model", model.first}, {"environment", a.environments.front().first},
                                      {"material", a.tableMaterials.back().first}});
  }
  if (truthSection) report["timings"]["truth_s"] = since(tTruth);
  const auto tShadow = Clock::now();
  std::vector<std::string> shadowNotes;
  if (shadowSection) report["shadow_truth"] = runShadowTruth(truthRun, shadowNotes);
  if (shadowSection) report["timings"]["shadow_truth_s"] = since(tShadow);
  const auto tRanked = Clock::now();
  if (rankingSection) report["methods_ranked"] = runMethodRanking(truthRun, shadowNotes);
  if (rankingSection) report["timings"]["methods_ranked_s"] = since(tRanked);
  for (const auto& n : shadowNotes) {
    log("note: " + n);
    report["notes"].push_back(n);
  }
  report["timings"]["total_s"] = since(tStart);

  // ---- report.json, then the figures from it, then report.md ---------------
  EvalResult result;
  const fs::path jsonPath = fs::path(o.outDir) / "report.json";
  std::ofstream(jsonPath) << report.dump(2) << '\n';
  if (!seedSections) {
    result.figures.problem = o.methodsOnly ? "--methods-only has no figures" : "--truth-only has no figures";
  } else if (o.figures) {
    // Unavailable is said by the command, last, where it is seen.
    result.figures = drawReportFigures(jsonPath);
    if (result.figures.status == FigureRun::Status::Drawn) {
      log("figures drawn by " + result.figures.script + " (" + fmt(result.figures.seconds, 1) + " s)");
    } else if (result.figures.status == FigureRun::Status::Failed) {
      log("error: the figures failed: " + result.figures.problem);
    }
  } else {
    result.figures.problem = "eval ran with --no-figures; draw them with `python3 tools/plot_report.py " +
                             jsonPath.string() + "`";
  }
  const bool drawn = result.figures.status == FigureRun::Status::Drawn;
  // The run's time is the reader's wait: the figures count, and report.json
  // is written again with them.
  if (result.figures.seconds > 0.0) report["timings"]["figures_s"] = result.figures.seconds;
  report["timings"]["total_s"] = since(tStart);
  std::ofstream(jsonPath) << report.dump(2) << '\n';

  std::ostringstream md;
  md << "# haarcast evaluation\n\nGenerated by `haarcast eval --data " << o.dataDir << " --out " << o.outDir
     << (o.quick ? " --quick" : "")
     << (o.shadowsOnly   ? " --shadows-only"
         : o.truthOnly   ? " --truth-only"
         : o.methodsOnly ? " --methods-only"
         : o.seedOnly    ? " --seed-only"
                         : "")
     << (options.models.empty() ? std::string() : " --models " + listed(options.models))
     << (options.tablesFrame > 0 ? " --tables-frame " + std::to_string(o.tablesFrame) : std::string())
     << (options.tablesRotations > 0 ? " --tables-rotations " + std::to_string(o.tablesRotations) : std::string())
     << (options.glossFrame > 0 ? " --gloss-frame " + std::to_string(o.glossFrame) : std::string())
     << (options.glossLevel > 0 ? " --gloss-level " + std::to_string(o.glossLevel) : std::string())
     << (o.methodsFrame > 0 ? " --methods-frame " + std::to_string(o.methodsFrame) : std::string())
     << (o.methodsLevel > 0 ? " --methods-level " + std::to_string(o.methodsLevel) : std::string()) << "` in "
     << formatDuration(report["timings"]["total_s"].get<double>()) << " (figures included) on "
     << describeMachine(report["config"]["machine"]) << ", load average "
     << report["config"]["machine"]["load_average_at_start"].get<std::string>()
     << " at the start. Every number is also in report.json; the figures are drawn from it by "
        "`tools/plot_report.py` (matplotlib).\n\n";
  for (const auto& n : report["notes"]) md << "- Note: " << n.get<std::string>() << "\n";
  if (!drawn && seedSections) md << "- **Figures not drawn:** " << result.figures.problem << ".\n";
  if (seedSections) {
    md << seedTablesMarkdown(report["seed_tables"], report["config"],
                             drawn ? report["figures"]["mse"] : nlohmann::json(nullptr));
    if (drawn) {
      md << "\nThe MSE figures share one logarithmic axis across variants, materials and levels, so that bar heights "
            "compare between figures: `refined` sits near float rounding, `faithful` many decades above it.\n";
    }
    const auto& g = report["glossiness"];
    md << "\n## Glossiness\n\n";
    if (drawn) md << "![glossiness](" << g["file"].get<std::string>() << ")\n\n";
    md << "Rows: " << listed(g["light_coefficients"]) << " light coefficients kept by `haar`; columns: "
       << listed(g["materials"]) << "; model " << g["model"].get<std::string>() << ", level " << g["level"].get<int>()
       << ", environment " << g["environment"].get<std::string>() << "; " << g["frame_size"].get<int>()
       << "² renders cropped to the " << g["tile_size"].get<int>() << "² square around the object (glossiness/).\n";
  }
  if (report.contains("truth")) md << methodTruthMarkdown(report["truth"]);
  if (report.contains("shadow_truth")) md << shadowTruthMarkdown(report["shadow_truth"]);
  if (report.contains("methods_ranked")) md << methodRankingMarkdown(report["methods_ranked"]);
  md << "\n## Timings\n\n" << timingsTable(report["timings"]);
  std::ofstream(fs::path(o.outDir) / "report.md") << md.str();
  result.report = std::move(report);
  return result;
}

std::function<int()> addEvalCommand(CLI::App& app) {
  auto options = std::make_shared<EvalOptions>();
  auto json = std::make_shared<bool>(false);
  auto* c = app.add_subcommand("eval", "Reproduce the seed's experiments; writes report.md, report.json and figures");
  c->add_option("--data", options->dataDir, "Data folder (probes/, meshes/, brdfs/); empty = built-in stand-ins");
  c->add_option("--out", options->outDir, "Output folder")->capture_default_str();
  c->add_flag("--quick", options->quick,
              "Every section, smaller (Tables 1–4 at levels 5 and 6 on four models, one rotation each, 24² frames): "
              "a few minutes on two cores");
  c->add_option("--models", options->models,
                "Models of Tables 1–4, of sphere, easter, venus, bunny, cat (default: all; --quick: all but the bunny)")
      ->delimiter(',');
  c->add_option("--tables-frame", options->tablesFrame,
                "Frame size of Tables 1–4 (0 = 24 with --quick, else 48)")->capture_default_str();
  c->add_option("--tables-rotations", options->tablesRotations,
                "Random rotations per model in Tables 1–4 (0 = 1 with --quick, else 2)")->capture_default_str();
  c->add_option("--gloss-frame", options->glossFrame,
                "Frame size of the glossiness renders, at least 128 (0 = 144 with --quick, else 256)")
      ->capture_default_str();
  c->add_option("--gloss-level", options->glossLevel,
                "Map level of the glossiness grid (0 = 5 with --quick, else 6)")->capture_default_str();
  c->add_flag("--seed-only", options->seedOnly,
              "Only the seed's experiments (Tables 1–4 beside the paper's, the MSE data, glossiness) and their figures");
  c->add_flag("--truth-only", options->truthOnly,
              "Only the truth sections (Monte Carlo against every method, and the shadow scenes)");
  c->add_flag("--shadows-only", options->shadowsOnly,
              "Only the shadow truth (the shadow scenes against the reference with every object occluding)");
  c->add_option("--truth-frame", options->truthFrame,
                "Frame size of the shadow truth (0 = 16 with --quick, else 64)")->capture_default_str();
  c->add_flag("--methods-only", options->methodsOnly,
              "Only the ranking of fused, haar, splitsum, table and matrix on speed, storage and truth "
              "(a rough, a glossy and a near-mirror sphere under a real probe)");
  c->add_option("--methods-frame", options->methodsFrame,
                "Frame size of the methods' ranking (0 = 16 with --quick, else 64)")->capture_default_str();
  c->add_option("--methods-level", options->methodsLevel,
                "Map level of the methods' ranking (0 = 4 with --quick, else 5)")->capture_default_str();
  c->add_flag("!--no-figures", options->figures,
              "Do not run tools/plot_report.py (matplotlib) on report.json");
  c->add_flag("--json", *json, "Print report.json to stdout");
  c->add_option("--threads", options->threads, "Worker threads (0 = all cores)");
  return [c, options, json]() {
    if (!c->parsed()) return -1;
    StderrProgress progress;
    const EvalResult result = runEval(*options, progress);
    if (*json) std::cout << result.report.dump(2) << '\n';
    std::fprintf(stderr, "wrote %s/report.md and report.json%s\n", options->outDir.c_str(),
                 result.figures.status == FigureRun::Status::Drawn ? " and the figures" : "");
    if (result.figures.status == FigureRun::Status::Unavailable && options->figures && !options->truthOnly &&
        !options->shadowsOnly && !options->methodsOnly) {
      std::fprintf(stderr, "figures not drawn: %s\n", result.figures.problem.c_str());
    }
    return result.figures.status == FigureRun::Status::Failed ? 1 : 0;
  };
}

}  // namespace haarcast::app
