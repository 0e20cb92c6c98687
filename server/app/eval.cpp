#include "eval.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include <glm/trigonometric.hpp>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/core/metrics.h"
#include "haarcast/io/mesh_io.h"
#include "haarcast/render/cpu_renderer.h"
#include "haarcast/render/exposure_meter.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"
#include "haarcast/render/tonemap.h"
#include "eval_methods.h"
#include "eval_truth.h"
#include "progress.h"
#include "report_figures.h"

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// The seed's averages (its Tables 1–4), for the report's comparison column.
const std::map<std::string, std::map<int, std::vector<double>>> kSeedTables = {
    {"alum-bronze", {{6, {110.82, 110.92, 111.54, 110.76, 111.02}}, {5, {111.17, 111.81, 112.56, 111.29, 111.62}}}},
    {"blue-metallic-paint", {{6, {104.28, 104.64, 104.97, 104.66, 104.73}}, {5, {105.49, 106.11, 106.20, 105.55, 105.49}}}}};
const char* kSeedEnvironments = "Galileo, Grace, RNL, St. Peter's, Uffizi";

template <typename T>
using NamedList = std::vector<std::pair<std::string, T>>;

// What the data folder offers, with built-in stand-ins for what is missing.
struct EvalAssets {
  NamedList<render::Environment> environments;
  NamedList<std::shared_ptr<Mesh>> models;
  NamedList<render::Material> tableMaterials;  // Tables 1–4: the seed's two
  NamedList<render::Material> glossMaterials;  // glossiness grid: steel, blue paint, aluminium bronze
  std::vector<std::string> notes;                // what was substituted
};

EvalAssets discoverAssets(const EvalOptions& o) {
  EvalAssets a;
  const fs::path data(o.dataDir);
  auto have = [&](const fs::path& p) { return !o.dataDir.empty() && fs::is_regular_file(data / p); };
  // The five probes standing in for the seed's five (DESIGN.md).
  for (const char* name : {"grace", "uffizi", "ennis", "pisa", "wells"}) {
    const fs::path p = fs::path("probes") / (std::string(name) + "_latlong_256x128.hdr");
    if (have(p)) a.environments.emplace_back(name, render::environmentFromFile((data / p).string()));
    if (o.quick && !a.environments.empty()) break;
  }
  if (a.environments.empty()) {
    a.environments.emplace_back("builtin-sky", render::builtinEnvironment());
    a.notes.push_back("no probes found: the built-in sky stands in for the five environments");
  }
  // Models: the seed's sphere, Easter (moai), Venus, bunny, cat.
  a.models.emplace_back("sphere", std::make_shared<Mesh>(assets::makeSphere(48)));
  if (!o.quick) {
    for (const auto& [name, file] : {std::pair{"easter", "moai.obj"}, std::pair{"venus", "venus.obj"},
                                     std::pair{"bunny", "bunny.ply"}, std::pair{"cat", "cat-low-resolution.obj"}}) {
      const fs::path p = fs::path("meshes") / file;
      if (!have(p)) continue;
      auto mesh = std::make_shared<Mesh>(io::loadMesh((data / p).string()));
      render::fitToUnitSphere(*mesh);
      a.models.emplace_back(name, mesh);
    }
    if (a.models.size() == 1) {
      a.models.emplace_back("torus", std::make_shared<Mesh>(assets::makeTorus(0.7, 0.3, 64, 32)));
      a.notes.push_back("no meshes found: a torus stands in for the seed's models");
    }
  }
  auto material = [&](const char* file, const char* fallback) {
    const fs::path p = fs::path("brdfs") / file;
    if (have(p)) return render::materialFromSpec((data / p).string());
    a.notes.push_back(std::string("no ") + file + ": " + fallback + " stands in");
    return render::materialFromSpec(fallback);
  };
  a.tableMaterials.emplace_back("alum-bronze", material("alum-bronze-sgd.binary", "ggx:0.3"));
  a.tableMaterials.emplace_back("blue-metallic-paint", material("blue-metallic-paint-sgd.binary", "phong:64"));
  a.glossMaterials.emplace_back("steel", material("chrome-steel-sgd.binary", "phong:512"));
  a.glossMaterials.push_back(a.tableMaterials[1]);
  a.glossMaterials.push_back(a.tableMaterials[0]);
  return a;
}

// One object at the origin in front of a camera that it nearly fills; named
// after its model, so that progress lines say which mesh is being prepared.
render::Scene singleObjectScene(const render::Environment& env, const std::string& name, std::shared_ptr<Mesh> mesh,
                                const render::Material& m, const glm::dvec3& rotateDegrees) {
  render::Scene s;
  s.environment = env;
  render::SceneObject o{name, std::move(mesh), m, {}};
  o.pose.rotateDegrees = rotateDegrees;
  s.objects.push_back(o);
  s.camera.eye = {0.0, 0.0, 3.0};
  s.camera.fovYDegrees = 42.0;
  return s;
}

// DESIGN.md PSNR over the object's pixels of linear RGB. An exact match is
// capped at 300 dB so that averages stay finite (and is rare: float noise).
ErrorStats objectError(const render::RenderResult& reference, const io::RgbImage& test,
                       const std::vector<std::uint8_t>& mask) {
  std::vector<double> ref, got;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    for (int c = 0; c < 3; ++c) {
      ref.push_back(reference.image.rgb[3 * i + static_cast<std::size_t>(c)]);
      got.push_back(test.rgb[3 * i + static_cast<std::size_t>(c)]);
    }
  }
  if (ref.empty()) throw std::runtime_error("eval: the object covers no pixel");
  ErrorStats e = compareSignals(ref, got);
  if (!std::isfinite(e.psnr)) e.psnr = 300.0;
  return e;
}

std::string fmt(double v, int digits = 2) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

// ["a", "b", 4] → "a, b, 4": lists in report.md's prose.
std::string listed(const nlohmann::json& array) {
  std::string out;
  for (const auto& v : array) out += (out.empty() ? "" : ", ") + (v.is_string() ? v.get<std::string>() : v.dump());
  return out;
}

// A square of the image: the object's bounding box (mask), grown by a
// margin and to a square, kept inside the image where it fits.
struct Square {
  int x = 0, y = 0, size = 0;
};

Square squareAround(const std::vector<std::uint8_t>& mask, int width, int height) {
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
  const int size = std::min(full, std::max(x1 - x0, y1 - y0) + 1 + 2 * margin);
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

std::string levelKey(int level) { return "level" + std::to_string(level); }

// The figure names, recorded in report.json: the script draws to them and
// report.md links them, so both read them from one place.
std::string msePlotName(int level, const std::string& material) {
  return "mse_level" + std::to_string(level) + "_" + material + ".png";
}

// report.md's timings: one row per stage of report.json's "timings".
std::string timingsTable(const nlohmann::json& timings) {
  const std::vector<std::pair<const char*, const char*>> rows = {
      {"tables_s", "Tables 1–4 and the MSE data"},
      {"glossiness_s", "glossiness grid"},
      {"truth_s", "truth PSNR (Monte Carlo and every method)"},
      {"shadow_truth_s", "shadow truth (three Monte Carlo renders per scene, fused and haar)"},
      {"methods_ranked_s", "methods ranked (two Monte Carlo renders per material, five methods)"}};
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
  row("loading the assets, writing report.json", std::max(0.0, total - stages));
  md << "| **total** | " << fmt(total, 1) << " | " << formatDuration(total) << " | |\n";
  return md.str();
}

}  // namespace

EvalResult runEval(const EvalOptions& options, ProgressReporter& progress) {
  EvalOptions o = options;
  if (o.methodsOnly && (o.truthOnly || o.shadowsOnly)) {
    throw std::invalid_argument("eval: --methods-only runs one section; it cannot go with --truth-only or --shadows-only");
  }
  o.truthOnly = o.truthOnly || o.shadowsOnly;
  // The sections: the seed's (tables, glossiness), the truth, the shadows,
  // the ranking of the methods; each flag keeps some of them.
  const bool seedSections = !o.truthOnly && !o.methodsOnly;
  const bool truthSection = !o.shadowsOnly && !o.methodsOnly;
  const bool shadowSection = !o.methodsOnly;
  const bool rankingSection = !o.shadowsOnly;
  const auto tStart = Clock::now();
  fs::create_directories(o.outDir);
  auto log = [&](const std::string& line) { progress.message("[eval] " + line); };
  const EvalAssets a = discoverAssets(o);
  for (const auto& n : a.notes) log("note: " + n);

  // Sizes: --quick is the test suite's; the full run fits 30 minutes here.
  const std::vector<int> levels = o.quick ? std::vector<int>{4} : std::vector<int>{5, 6};
  const int frame = o.quick ? 20 : 48;
  const int rotations = o.quick ? 1 : 2;
  render::RenderOptions base;
  base.width = base.height = frame;
  base.lightCoefficients = 1u << 20;  // all: the tables isolate rotation error
  base.environmentBackground = false;
  base.visibility.supersampling = 1;
  base.cacheDir = (fs::path(o.outDir) / "cache").string();
  base.threads = o.threads;
  // The renders' own long stages (visibility of a new mesh) show inside ours.
  const StageProgress inner = progress.callback();

  nlohmann::json report;
  report["config"] = {{"quick", o.quick}, {"frame", frame}, {"rotations_per_model", rotations}, {"levels", levels}};
  for (const auto& [name, env] : a.environments) report["config"]["environments"].push_back(name);
  for (const auto& [name, m] : a.models) report["config"]["models"].push_back(name);
  for (const auto& [name, m] : a.tableMaterials) report["config"]["table_materials"].push_back(name);
  report["notes"] = a.notes;

  // ---- Tables 1–4 and the MSE data ----------------------------------------
  const auto tTables = Clock::now();
  if (seedSections) {
  const std::vector<glm::dvec3> poses = [&] {
    std::vector<glm::dvec3> p;
    for (const EulerYXY& r : randomRotations(rotations * static_cast<int>(a.models.size()), 2026u)) {
      p.push_back(glm::degrees(glm::dvec3(r.beta, r.alpha, r.gamma)));
    }
    return p;
  }();
  const std::string stage = "eval tables 1–4";
  const std::size_t renders = levels.size() * a.tableMaterials.size() * a.environments.size() * a.models.size() *
                              static_cast<std::size_t>(rotations);
  std::size_t rendered = 0;
  progress.update(stage, 0, renders);
  for (int level : levels) {
    for (const auto& [matName, material] : a.tableMaterials) {
      for (const auto& [envName, env] : a.environments) {
        double sumRefined = 0.0, sumFaithful = 0.0;
        int count = 0;
        for (std::size_t mi = 0; mi < a.models.size(); ++mi) {
          double modelMseRefined = 0.0, modelMseFaithful = 0.0;
          for (int r = 0; r < rotations; ++r) {
            const render::Scene scene =
                singleObjectScene(env, a.models[mi].first, a.models[mi].second, material,
                                  poses[mi * static_cast<std::size_t>(rotations) + static_cast<std::size_t>(r)]);
            render::RenderOptions opt = base;
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
            modelMseRefined += refined.mse / rotations;
            modelMseFaithful += faithful.mse / rotations;
            ++count;
            // The stage ends after its last result line, below.
            if (++rendered < renders) progress.update(stage, rendered, renders);
          }
          report["mse"][levelKey(level)][matName][envName][a.models[mi].first] = {
              {"refined", modelMseRefined}, {"faithful", modelMseFaithful}};
        }
        report["tables"][levelKey(level)][matName][envName] = {
            {"refined", sumRefined / count}, {"faithful", sumFaithful / count}};
        log("table level " + std::to_string(level) + " " + matName + " " + envName + ": refined " +
            fmt(sumRefined / count) + " dB, faithful " + fmt(sumFaithful / count) + " dB");
      }
      report["figures"]["mse"][levelKey(level)][matName] = msePlotName(level, matName);
    }
  }
  progress.update(stage, renders, renders);
  }
  if (seedSections) report["timings"]["tables_s"] = since(tTables);

  // ---- Glossiness grid: materials × light coefficients -------------------
  // Each tile is a PNG of its own (glossiness/); the script lays them out
  // with their labels. Every tile is cropped to the same square around the
  // object (the union of the renders' object masks), so that the object,
  // not the background, fills the sheet and the tiles still line up.
  const auto tGloss = Clock::now();
  if (seedSections) {
    const int glossLevel = o.quick ? 4 : 6;
    const int frameSize = o.quick ? 32 : 256;
    const std::vector<std::size_t> ks = {4, 16, 64, 256};
    const auto& model = a.models.size() > 3 ? a.models[3] : a.models.front();  // the bunny when there is one
    const std::string stage = "eval glossiness";
    const std::size_t renders = a.glossMaterials.size() * ks.size();
    std::size_t rendered = 0;
    progress.update(stage, 0, renders);
    fs::create_directories(fs::path(o.outDir) / "glossiness");
    std::vector<std::vector<io::RgbImage>> byMaterial;  // [material][k]
    std::vector<std::uint8_t> covered(static_cast<std::size_t>(frameSize * frameSize), 0);
    for (const auto& [matName, material] : a.glossMaterials) {
      byMaterial.emplace_back();
      for (std::size_t k : ks) {
        render::RenderOptions opt = base;
        opt.level = glossLevel;
        opt.width = opt.height = frameSize;
        opt.lightCoefficients = k;
        render::RenderResult r = render::renderCpu(
            singleObjectScene(a.environments.front().second, model.first, model.second, material, {0.0, 20.0, 0.0}),
            opt, inner);
        for (std::size_t i = 0; i < covered.size(); ++i) covered[i] |= r.objectMask[i];
        byMaterial.back().push_back(std::move(r.image));
        progress.update(stage, ++rendered, renders);
      }
    }
    const Square crop = squareAround(covered, frameSize, frameSize);
    nlohmann::json tiles = nlohmann::json::array();  // [row = k][column = material]
    for (std::size_t row = 0; row < ks.size(); ++row) tiles.push_back(nlohmann::json::array());
    for (std::size_t m = 0; m < a.glossMaterials.size(); ++m) {
      // One exposure per material, from its richest render, through the
      // display transform every haarcast image uses (render/tonemap.h).
      const double stops = render::meterExposure(byMaterial[m].back(), covered, {}, render::ToneCurve::Reinhard).stops;
      for (std::size_t row = 0; row < ks.size(); ++row) {
        const std::string file = "glossiness/k" + std::to_string(ks[row]) + "_" + a.glossMaterials[m].first + ".png";
        const io::RgbImage tile = cropped(byMaterial[m][row], crop);
        io::writePngRgba8((fs::path(o.outDir) / file).string(), render::tonemapRgba8(tile, stops), tile.width, tile.height);
        tiles[row].push_back(file);
      }
    }
    report["glossiness"] = {{"file", "glossiness.png"}, {"model", model.first}, {"level", glossLevel},
                            {"environment", a.environments.front().first}, {"light_coefficients", ks},
                            {"frame_size", frameSize}, {"tile_size", crop.size}, {"tiles", tiles}};
    for (const auto& [name, m] : a.glossMaterials) report["glossiness"]["materials"].push_back(name);
  }
  if (seedSections) report["timings"]["glossiness_s"] = since(tGloss);

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

  std::ostringstream md;
  md << "# haarcast evaluation\n\nGenerated by `haarcast eval --data " << o.dataDir << " --out " << o.outDir
     << (o.quick ? " --quick" : "")
     << (o.shadowsOnly ? " --shadows-only" : o.truthOnly ? " --truth-only" : o.methodsOnly ? " --methods-only" : "")
     << (o.methodsFrame > 0 ? " --methods-frame " + std::to_string(o.methodsFrame) : std::string())
     << (o.methodsLevel > 0 ? " --methods-level " + std::to_string(o.methodsLevel) : std::string()) << "` in "
     << formatDuration(report["timings"]["total_s"].get<double>())
     << ". Every number is also in report.json; the figures are drawn from it by `tools/plot_report.py` "
        "(matplotlib).\n\n";
  for (const auto& n : report["notes"]) md << "- Note: " << n.get<std::string>() << "\n";
  if (!drawn && seedSections) md << "- **Figures not drawn:** " << result.figures.problem << ".\n";
  if (seedSections) {
  md << "\n## Tables 1–4: average seed PSNR (dB)\n\nSeed PSNR = PSNR of the `haar` render against the same render with "
        "`spatial` rotation, over the object's pixels (DESIGN.md), averaged over the models ("
     << listed(report["config"]["models"]) << ") × " << rotations << " random rotations each; frames " << frame << "², "
     << "all light coefficients. `refined` is haar's default, `faithful` the seed as written. The seed's own averages "
        "are for its environments ("
     << kSeedEnvironments << ").\n";
  for (int level : levels) {
    for (const auto& [matName, material] : a.tableMaterials) {
      md << "\n### " << matName << ", level " << level << "\n\n| variant |";
      for (const auto& [envName, env] : a.environments) md << ' ' << envName << " |";
      md << "\n|---|";
      for (std::size_t e = 0; e < a.environments.size(); ++e) md << "---|";
      for (const char* variant : {"refined", "faithful"}) {
        md << "\n| " << variant << " |";
        for (const auto& [envName, env] : a.environments)
          md << ' ' << fmt(report["tables"][levelKey(level)][matName][envName][variant].get<double>()) << " |";
      }
      const auto seedIt = kSeedTables.find(matName);
      if (seedIt != kSeedTables.end() && seedIt->second.count(level)) {
        md << "\n| seed (its probes) |";
        const auto& seed = seedIt->second.at(level);
        for (std::size_t e = 0; e < a.environments.size(); ++e) md << ' ' << (e < seed.size() ? fmt(seed[e]) : "") << " |";
      }
      md << "\n";
      if (drawn) {
        const std::string file = report["figures"]["mse"][levelKey(level)][matName].get<std::string>();
        md << "\n![MSE of haar against spatial, " << matName << ", level " << level << "](" << file << ")\n";
      }
    }
  }
  if (drawn) {
    md << "\nThe MSE figures share one logarithmic axis across variants, materials and levels, so that bar heights "
          "compare between figures: `refined` sits near float rounding, `faithful` many decades above it.\n";
  }
  const auto& g = report["glossiness"];
  md << "\n## Glossiness\n\n";
  if (drawn) md << "![glossiness](" << g["file"].get<std::string>() << ")\n\n";
  md << "Rows: " << listed(g["light_coefficients"]) << " light coefficients; columns: " << listed(g["materials"])
     << "; model " << g["model"].get<std::string>() << ", level " << g["level"].get<int>() << ", environment "
     << g["environment"].get<std::string>() << "; " << g["frame_size"].get<int>() << "² renders cropped to the "
     << g["tile_size"].get<int>() << "² square around the object (glossiness/).\n";
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
  c->add_flag("--quick", options->quick, "The small version the test suite runs");
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
