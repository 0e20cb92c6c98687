#include "eval_truth.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>
#include <utility>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/core/metrics.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/io/mesh_io.h"
#include "haarcast/cpu/reference.h"
#include "number_format.h"
#include "truth_metrics.h"

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string fmtSig(double v, int digits = 3) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

std::string levelKey(int level) { return "level" + std::to_string(level); }

}  // namespace

render::ReferenceOptions truthReferenceOptions(const TruthRun& run, int frame, double tolerance, std::size_t maxSamples,
                                               bool coarseQuickTables) {
  render::ReferenceOptions ro;
  ro.width = ro.height = frame;
  ro.environmentBackground = false;
  ro.tolerance = tolerance;
  ro.maxSamples = maxSamples;
  ro.threads = run.options.threads;
  if (coarseQuickTables && run.options.quick) {
    ro.environmentTableWidth = 256;
    ro.brdfTableWidth = 64;
    ro.brdfTableThetaOut = 8;
  }
  return ro;
}

render::ReferenceResult monteCarlo(const TruthRun& run, const render::Scene& scene, const render::ReferenceOptions& ro,
                                   const std::string& stage) {
  const render::ReferenceResult r =
      render::renderReference(scene, ro, monteCarloProgress(run.progress, stage, ro.tolerance, ro.maxSamples));
  run.progress.finish(stage);
  return r;
}

// ---- The methods on one glossy object ------------------------------------
// The sphere in the first environment with the second table material (blue
// paint): the configuration whose Monte Carlo converges within the budget
// here (alum-bronze's narrow lobe against Grace's 2000:1 windows does not:
// half-image difference 0.17 at 4096 samples). The truth's own noise is
// reported beside it: a truth PSNR near that floor measures the noise.
nlohmann::json runMethodTruth(const TruthRun& run, const render::Scene& scene, nlohmann::json config) {
  const EvalOptions& o = run.options;
  const render::ReferenceOptions ro =
      truthReferenceOptions(run, o.quick ? 16 : 48, o.quick ? 0.05 : 0.01, o.quick ? 256 : 65536, false);
  const render::ReferenceResult mc = monteCarlo(run, scene, ro, "eval truth: Monte Carlo");
  // The average of two halves differing by RMS d has an error of RMS d/2.
  double mean = 0.0, peak = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < mc.objectMask.size(); ++i) {
    if (!mc.objectMask[i]) continue;
    for (int c = 0; c < 3; ++c) {
      const double v = mc.image.rgb[3 * i + static_cast<std::size_t>(c)];
      mean += v;
      peak = std::max(peak, v);
      ++n;
    }
  }
  mean /= static_cast<double>(std::max<std::size_t>(n, 1));
  const double noiseRms = 0.5 * mc.halfError * mean;
  const double noiseFloor = 20.0 * std::log10(peak / noiseRms);
  run.log("truth: Monte Carlo " + std::to_string(mc.samples) + " samples, half error " + fmt(mc.halfError, 4) +
          ", noise floor " + fmt(noiseFloor) + " dB, " + fmt(mc.seconds, 1) + " s");
  nlohmann::json truth;
  config["frame"] = ro.width;
  config["mc_samples"] = mc.samples;
  config["mc_half_error"] = mc.halfError;
  config["mc_noise_floor_psnr"] = noiseFloor;
  truth["config"] = std::move(config);
  struct Variant {
    std::string name;
    RotationMethod method;
    HaarVariant variant;
  };
  // fused with and without the θₒ slice blend; level 7 for fused alone
  // (the rotating methods there cost minutes and add nothing new).
  const std::vector<Variant> variants = {Variant{"fused", RotationMethod::Fused, HaarVariant::Refined},
                                         Variant{"fused/nearest", RotationMethod::Fused, HaarVariant::Refined},
                                         Variant{"haar", RotationMethod::Haar, HaarVariant::Refined},
                                         Variant{"haar/faithful", RotationMethod::Haar, HaarVariant::Faithful},
                                         Variant{"spatial", RotationMethod::Spatial, HaarVariant::Refined},
                                         Variant{"matrix", RotationMethod::Matrix, HaarVariant::Refined},
                                         Variant{"table", RotationMethod::Table, HaarVariant::Refined}};
  const std::vector<int> truthLevels = o.quick ? std::vector<int>{4} : std::vector<int>{5, 6, 7};
  auto runs = [&](int level, const Variant& v) { return level <= 6 || v.method == RotationMethod::Fused; };
  std::size_t renders = 0, rendered = 0;
  for (int level : truthLevels)
    for (const Variant& v : variants) renders += runs(level, v) ? 1 : 0;
  const std::string stage = "eval truth: methods";
  const StageProgress inner = run.progress.callback();
  run.progress.update(stage, 0, renders);
  for (int level : truthLevels) {
    for (const Variant& v : variants) {
      if (!runs(level, v)) continue;
      render::RenderOptions opt = run.base;
      opt.interpolateSlices = v.name != "fused/nearest";
      opt.level = level;
      opt.width = ro.width;
      opt.height = ro.height;
      opt.method = v.method;
      opt.rotator.haarVariant = v.variant;
      const auto t = Clock::now();
      const render::RenderResult r = render::renderCpu(scene, opt, inner);
      const TruthError e = compareWithTruth(mc.image.rgb, r.image.rgb, mc.objectMask, {});
      truth[levelKey(level)][v.name] = {{"psnr", e.psnr}, {"mse", e.mse}, {"seconds", since(t)}};
      run.log("truth level " + std::to_string(level) + " " + v.name + ": " + fmt(e.psnr) + " dB");
      run.progress.update(stage, ++rendered, renders);
    }
  }
  return truth;
}

std::string methodTruthMarkdown(const nlohmann::json& truth) {
  const auto& tc = truth["config"];
  std::ostringstream md;
  md << "\n## Truth PSNR against Monte Carlo\n\nModel " << tc["model"].get<std::string>() << ", environment "
     << tc["environment"].get<std::string>() << ", material " << tc["material"].get<std::string>() << ", "
     << tc["frame"].get<int>() << "² frames. The Monte Carlo render took " << tc["mc_samples"].get<int>()
     << " samples per pixel; its half-images differ by " << fmt(tc["mc_half_error"].get<double>(), 4)
     << ", so its own noise allows at most " << fmt(tc["mc_noise_floor_psnr"].get<double>())
     << " dB: figures near that floor measure the noise, not the method.\n\n"
        "| level | method | truth PSNR (dB) | MSE | seconds |\n|---|---|---:|---:|---:|\n";
  for (const auto& [key, methods] : truth.items()) {
    if (key == "config") continue;
    for (const auto& [name, v] : methods.items()) {
      md << "| " << key.substr(5) << " | " << name << " | " << fmt(v["psnr"].get<double>()) << " | "
         << fmtSig(v["mse"].get<double>()) << " | " << fmt(v["seconds"].get<double>(), 2) << " |\n";
    }
  }
  return md.str();
}

// ---- Shadow scenes ----------------------------------------------------------

// A torus (assets::makeTorus) less the sector of `gapDegrees` about +X:
// an open tube, both ends open, whose inside the rays can reach.
Mesh openTube(double majorRadius, double minorRadius, double gapDegrees) {
  Mesh torus = assets::makeTorus(majorRadius, minorRadius, 96, 24);
  const double half = 0.5 * gapDegrees * kPi / 180.0;
  std::vector<glm::uvec3> kept;
  for (const glm::uvec3& t : torus.triangles) {
    const glm::vec3 c = (torus.positions[t.x] + torus.positions[t.y] + torus.positions[t.z]) / 3.0f;
    if (std::abs(std::atan2(static_cast<double>(c.z), static_cast<double>(c.x))) > half) kept.push_back(t);
  }
  torus.triangles = std::move(kept);
  torus.name = "open tube";
  return torus;
}

render::Scene groundedScene(const render::Environment& environment, std::vector<render::SceneObject> objects,
                            double groundHalfSize, int groundSubdivisions) {
  render::Scene s;
  s.environment = environment;
  // The scene's ground (SceneObject::ground): `fused` shades it in closed
  // form and lets it take the objects' shadows; the reference sees a plane.
  render::SceneObject ground{"ground", std::make_shared<Mesh>(assets::makePlane(groundHalfSize, groundSubdivisions)),
                             render::materialFromSpec("lambert"), {}};
  ground.ground = true;
  ground.groundAlbedo = glm::dvec3(0.8);  // materialFromSpec("lambert")'s albedo
  s.objects.push_back(std::move(ground));
  for (render::SceneObject& o : objects) s.objects.push_back(std::move(o));
  return s;
}

std::vector<ShadowScene> shadowScenes(const EvalOptions& o, std::vector<std::string>& notes) {
  std::vector<ShadowScene> out;
  const render::Environment suns = render::sunsEnvironment();
  // Pillars: slots 2–6 times deeper than wide, seen from 33° above so that
  // their floors and the pillars' sides are in view, each sun casting its own
  // shadow down them. --quick: fewer vertices per face (faster visibility).
  auto pillars = std::make_shared<Mesh>(assets::makePillars(4, o.quick ? 2 : 6));
  render::fitToUnitSphere(*pillars);
  for (const auto& [name, material] : {std::pair{"pillars-lambert", "lambert"}, std::pair{"pillars-ggx", "ggx:0.3"}}) {
    if (o.quick && std::string(material) != "lambert") continue;
    ShadowScene sc{name, std::string("4×4 pillars on a slab (makePillars), ") + material + ", suns sky", "suns", {}};
    sc.scene.environment = suns;
    render::SceneObject obj{"pillars", pillars, render::materialFromSpec(material), {}};
    obj.pose.rotateDegrees = {0.0, 25.0, 0.0};
    sc.scene.objects.push_back(std::move(obj));
    sc.scene.camera.eye = {0.0, 1.7, 2.6};
    sc.scene.camera.target = {0.0, 0.0, 0.0};
    sc.scene.camera.fovYDegrees = 45.0;
    out.push_back(std::move(sc));
  }
  // A Lambert ball and a tilted GGX torus standing 1 cm above a ground.
  {
    render::SceneObject ball{"ball", std::make_shared<Mesh>(assets::makeSphere(48)), render::materialFromSpec("lambert"), {}};
    ball.pose.scale = 0.45;
    ball.pose.translate = {-0.6, 0.46, 0.1};
    // R = 1, r = 0.35 tilted 30° about X: lowest point (sin 30° + 0.35)·0.45 = 0.3825 below its centre.
    render::SceneObject torus{"torus", std::make_shared<Mesh>(assets::makeTorus(1.0, 0.35, 64, 32)),
                              render::materialFromSpec("ggx:0.3"), {}};
    torus.pose.scale = 0.45;
    torus.pose.rotateDegrees = {30.0, 20.0, 0.0};
    torus.pose.translate = {0.65, 0.3925, -0.1};
    ShadowScene sc{"grounded", "a Lambert ball and a GGX 0.3 torus on a Lambert ground (groundedScene), suns sky",
                   "suns", groundedScene(suns, {ball, torus}, 3.0, o.quick ? 16 : 64)};
    sc.scene.camera.eye = {0.0, 1.4, 3.0};
    sc.scene.camera.target = {0.0, 0.25, 0.0};
    sc.scene.camera.fovYDegrees = 40.0;
    out.push_back(std::move(sc));
  }
  // An open mesh on the ground beside a glossy ball: a torus with a sector
  // cut away (its tube open at both ends, so rays enter it), lying on the
  // ground, Lambert, 5 cm from a GGX 0.1 ball. Where the tube meets the
  // ground the ground's hidden sky must see through its open ends, and the
  // tube's side and the ball hide sky from each other.
  if (!o.quick) {
    render::SceneObject tube{"open tube", std::make_shared<Mesh>(openTube(1.0, 0.3, 100.0)), render::materialFromSpec("lambert"), {}};
    tube.pose.scale = 0.5;
    tube.pose.rotateDegrees = {0.0, 150.0, 0.0};  // the cut toward the back left
    tube.pose.translate = {-0.35, 0.15, 0.0};  // its lowest point r·scale = 0.15 below its centre
    render::SceneObject ball{"ball", std::make_shared<Mesh>(assets::makeSphere(48)), render::materialFromSpec("ggx:0.1"), {}};
    ball.pose.scale = 0.35;
    // 5 cm from the tube: the tube's core circle (radius 0.5, height 0.15)
    // is √((1.012 − 0.5)² + 0.2²) = 0.55 from the ball's centre.
    ball.pose.translate = {0.662, 0.35, 0.0};
    ShadowScene sc{"open-tube", "an open Lambert tube (a torus less 100°) beside a GGX 0.1 ball on a Lambert ground, suns sky",
                   "suns", groundedScene(suns, {tube, ball}, 3.0, o.quick ? 16 : 64)};
    sc.scene.camera.eye = {0.3, 1.3, 2.6};
    sc.scene.camera.target = {0.0, 0.15, 0.0};
    sc.scene.camera.fovYDegrees = 40.0;
    out.push_back(std::move(sc));
  }
  // Two objects close together: a Lambert box and a Lambert ball 5 cm
  // apart on the ground, the gap between them in view.
  if (!o.quick) {
    render::SceneObject box{"box", std::make_shared<Mesh>(assets::makeBox(0.35, 0.35, 0.35)), render::materialFromSpec("lambert"), {}};
    box.pose.rotateDegrees = {0.0, 15.0, 0.0};
    box.pose.translate = {-0.4, 0.35, 0.0};
    render::SceneObject ball{"ball", std::make_shared<Mesh>(assets::makeSphere(48)), render::materialFromSpec("lambert"), {}};
    ball.pose.scale = 0.4;
    ball.pose.translate = {0.43, 0.4, 0.0};  // (0.83, 0, 0)·(cos 15°, 0, −sin 15°) − 0.35 − 0.4 = 5 cm from the box's face
    ShadowScene sc{"close-pair", "a Lambert box and a Lambert ball 5 cm apart on a Lambert ground, suns sky", "suns",
                   groundedScene(suns, {box, ball}, 3.0, o.quick ? 16 : 64)};
    sc.scene.camera.eye = {0.0, 0.9, 2.4};
    sc.scene.camera.target = {0.0, 0.3, 0.0};
    sc.scene.camera.fovYDegrees = 40.0;
    out.push_back(std::move(sc));
  }
  // The bunny in Grace: a real mesh's own shadows (ears, chin, haunch).
  if (!o.quick) {
    const fs::path data(o.dataDir);
    auto have = [&](const fs::path& p) { return !o.dataDir.empty() && fs::is_regular_file(data / p); };
    fs::path probe;
    for (const char* p : {"probes/grace_latlong_256x128.hdr", "probes/grace_latlong.exr"}) {
      if (probe.empty() && have(p)) probe = p;
    }
    if (have("meshes/bunny.ply") && !probe.empty()) {
      auto bunny = std::make_shared<Mesh>(io::loadMesh((data / "meshes/bunny.ply").string()));
      render::fitToUnitSphere(*bunny);
      ShadowScene sc{"bunny-grace", "the bunny, Lambert, Grace (" + probe.filename().string() + ")",
                     probe.filename().string(), {}};
      sc.scene.environment = render::environmentFromFile((data / probe).string());
      render::SceneObject obj{"bunny", bunny, render::materialFromSpec("lambert"), {}};
      obj.pose.rotateDegrees = {0.0, 20.0, 0.0};
      sc.scene.objects.push_back(std::move(obj));
      sc.scene.camera.eye = {0.0, 0.0, 3.0};
      sc.scene.camera.fovYDegrees = 42.0;
      out.push_back(std::move(sc));
    } else {
      notes.push_back("no meshes/bunny.ply or Grace probe in the data folder: shadow truth without bunny-grace");
    }
  }
  return out;
}

nlohmann::json runShadowTruth(const TruthRun& run, std::vector<std::string>& notes) {
  const EvalOptions& o = run.options;
  const int frame = o.truthFrame > 0 ? o.truthFrame : (o.quick ? 16 : 64);
  const render::ReferenceOptions ro = truthReferenceOptions(run, frame, o.quick ? 0.05 : 0.01, o.quick ? 256 : 16384, true);
  // The product's defaults (light k, visibility, slice blend, the sum by
  // cells), as `render` draws; "fused/all-k" keeps every light coefficient
  // and "fused/every-direction" sums every direction (sumTolerance 0), so
  // that the light's truncation, the sum by cells and the rest separate.
  render::RenderOptions defaults;
  defaults.sumTolerance = shared::kDefaultSumTolerance;
  defaults.width = defaults.height = frame;
  defaults.environmentBackground = false;
  defaults.cacheDir = run.base.cacheDir;
  defaults.threads = run.base.threads;
  struct Variant {
    std::string name;
    RotationMethod method;
    bool allLight;
    bool everyDirection = false;
  };
  const std::vector<Variant> variants = {{"fused", RotationMethod::Fused, false},
                                         {"fused/all-k", RotationMethod::Fused, true},
                                         {"fused/every-direction", RotationMethod::Fused, false, true},
                                         {"haar", RotationMethod::Haar, false}};
  const std::vector<int> levels = o.quick ? std::vector<int>{4} : std::vector<int>{5, 6};

  nlohmann::json out;
  out["config"] = {{"frame", frame},
                   {"tolerance", ro.tolerance},
                   {"max_samples", ro.maxSamples},
                   {"levels", levels},
                   {"shadow_threshold", kShadowThreshold},
                   {"render_defaults", {{"light_coefficients", defaults.lightCoefficients},
                                        {"visibility_supersampling", defaults.visibility.supersampling},
                                        {"visibility_keep", defaults.visibility.keep},
                                        {"theta_samples", defaults.thetaSamples},
                                        {"sum_tolerance", defaults.sumTolerance}}}};
  const StageProgress inner = run.progress.callback();
  for (const ShadowScene& sc : shadowScenes(o, notes)) {
    const auto tScene = Clock::now();
    nlohmann::json& js = out["scenes"][sc.name];
    js["description"] = sc.description;
    js["environment"] = sc.environment;
    const std::string stage = "eval shadow truth " + sc.name;
    render::ReferenceOptions a = ro;
    a.seed = 1;
    const render::ReferenceResult truth = monteCarlo(run, sc.scene, a, stage + ": Monte Carlo");
    // The floor and the unoccluded twin: exactly the truth's sample count.
    render::ReferenceOptions b = ro;
    b.seed = 2;
    b.tolerance = 0.0;
    b.maxSamples = truth.samples;
    const render::ReferenceResult second = monteCarlo(run, sc.scene, b, stage + ": second truth");
    render::ReferenceOptions n = ro;
    n.seed = 1;
    n.tolerance = 0.0;
    n.maxSamples = truth.samples;
    n.occlusion = render::ReferenceOcclusion::None;
    const render::ReferenceResult open = monteCarlo(run, sc.scene, n, stage + ": unoccluded");
    const std::vector<std::uint8_t> shadowed = shadowedPixels(truth.image.rgb, open.image.rgb, truth.objectMask);
    const TruthError floor = compareWithTruth(truth.image.rgb, second.image.rgb, truth.objectMask, shadowed);
    js["mc"] = {{"samples", truth.samples},          {"half_error", truth.halfError},
                {"seconds", truth.seconds},          {"second_seconds", second.seconds},
                {"unoccluded_seconds", open.seconds}};
    js["floor"] = toJson(floor);
    js["floor"]["dark_ground"] = toJson(darkPixels(truth.image.rgb, open.image.rgb, second.image.rgb, truth.groundMask));
    run.log("shadow truth " + sc.name + ": " + std::to_string(truth.samples) + " samples, half error " +
            fmt(truth.halfError, 4) + "; floor " + fmt(floor.psnr) + " dB, relative L2 " + fmt(floor.relativeL2, 4) +
            "; shadowed " + fmt(100.0 * floor.shadowed.pixelFraction, 1) + " % of the pixels");
    const std::size_t renders = levels.size() * variants.size();
    std::size_t rendered = 0;
    run.progress.update(stage + ": methods", 0, renders);
    for (int level : levels) {
      for (const Variant& v : variants) {
        render::RenderOptions opt = defaults;
        opt.level = level;
        opt.method = v.method;
        if (v.allLight) opt.lightCoefficients = 1u << 20;
        if (v.everyDirection) opt.sumTolerance = 0.0f;
        const auto t = Clock::now();
        const render::RenderResult r = render::renderCpu(sc.scene, opt, inner);
        const TruthError e = compareWithTruth(truth.image.rgb, r.image.rgb, truth.objectMask, shadowed);
        nlohmann::json j = toJson(e);
        const DarkPixels dark = darkPixels(truth.image.rgb, open.image.rgb, r.image.rgb, truth.groundMask);
        j["dark_ground"] = toJson(dark);
        j["seconds"] = since(t);
        js["methods"][levelKey(level)][v.name] = std::move(j);
        run.log("shadow truth " + sc.name + " level " + std::to_string(level) + " " + v.name + ": " + fmt(e.psnr) +
                " dB, relative L2 " + fmt(e.relativeL2, 4) + ", brightness " + fmt(e.brightness, 4) +
                "; shadowed pixels hold " + fmt(100.0 * e.shadowed.errorShare, 1) + " % of the squared error; " +
                std::to_string(dark.dark) + " of " + std::to_string(dark.eligible) + " mostly lit ground pixels over " +
                fmt(100.0 * kDarkDrop, 0) + " % too dark");
        run.progress.update(stage + ": methods", ++rendered, renders);
      }
    }
    js["seconds"] = since(tScene);
  }
  return out;
}

std::string shadowTruthMarkdown(const nlohmann::json& st) {
  const auto& c = st["config"];
  std::ostringstream md;
  md << "\n## Shadows: truth with every object occluding\n\n"
     << c["frame"].get<int>() << "² frames, object pixels, linear RGB. The truth is the Monte Carlo reference with "
        "every object of the scene occluding (`--occlusion scene`), converged to a half-image difference of "
     << fmt(c["tolerance"].get<double>(), 3) << " (at most " << c["max_samples"].get<int>()
     << " samples). **Floor**: a second truth (another seed, the same samples) against the first; a method at "
        "the floor is as close as the truth's own noise allows. **Shadowed**: pixels whose truth is over "
     << fmt(100.0 * c["shadow_threshold"].get<double>(), 0)
     << " % darker in luminance than the same samples with nothing occluding (`--occlusion none`); **lit**: the "
        "rest. For each: the share of the pixels and of the squared error, relative L2 = sqrt(Σ(a − r)²/Σr²) and "
        "brightness Σa/Σr. Methods at the product's defaults (k = "
     << c["render_defaults"]["light_coefficients"].get<std::size_t>() << " light coefficients, visibility "
     << c["render_defaults"]["visibility_supersampling"].get<int>() << "² supersampled, "
     << c["render_defaults"]["visibility_keep"].get<std::size_t>()
     << " coefficients per vertex); `fused/all-k` keeps every light coefficient. **Dark ground**: of the ground's "
        "pixels whose truth keeps more than "
     << fmt(100.0 * kDarkKeptShare, 0) << " % of its unoccluded luminance, how many the method draws over "
     << fmt(100.0 * kDarkDrop, 0) << " % darker than the truth (and the lowest ratio render / truth among them).\n";
  if (!st.contains("scenes")) return md.str();
  // "dark / eligible (worst ratio)", or "—" for a scene without a ground.
  auto darkCell = [](const nlohmann::json& e) -> std::string {
    if (!e.contains("dark_ground") || e["dark_ground"]["eligible"].get<std::size_t>() == 0) return "—";
    const auto& d = e["dark_ground"];
    return std::to_string(d["dark"].get<std::size_t>()) + " / " + std::to_string(d["eligible"].get<std::size_t>()) +
           " (" + fmt(d["worst_ratio"].get<double>(), 2) + ")";
  };
  auto row = [&](const std::string& level, const std::string& name, const nlohmann::json& e, const std::string& s) {
    const auto& sh = e["shadowed"];
    const auto& li = e["lit"];
    md << "| " << level << " | " << name << " | " << fmt(e["psnr"].get<double>()) << " | "
       << fmt(100.0 * e["relative_l2"].get<double>()) << " % | " << fmt(e["brightness"].get<double>(), 3) << " | "
       << fmt(100.0 * sh["pixel_fraction"].get<double>(), 1) << " % | " << fmt(100.0 * sh["error_share"].get<double>(), 1)
       << " % | " << fmt(100.0 * sh["relative_l2"].get<double>()) << " % | " << fmt(sh["brightness"].get<double>(), 3)
       << " | " << fmt(100.0 * li["relative_l2"].get<double>()) << " % | " << fmt(li["brightness"].get<double>(), 3)
       << " | " << darkCell(e) << " | " << s << " |\n";
  };
  for (const auto& [name, sc] : st["scenes"].items()) {
    md << "\n### " << name << "\n\n" << sc["description"].get<std::string>() << ". Truth: "
       << sc["mc"]["samples"].get<int>() << " samples per pixel, half-image difference "
       << fmt(sc["mc"]["half_error"].get<double>(), 4) << ", " << fmt(sc["mc"]["seconds"].get<double>(), 1)
       << " s (and as long again for each of the floor and the unoccluded render).\n\n"
          "| level | method | PSNR (dB) | rel. L2 | brightness | shadowed px | shadowed err | shadowed rel. L2 | "
          "shadowed bright. | lit rel. L2 | lit bright. | dark ground | s |\n"
          "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    row("", "floor (2nd truth)", sc["floor"], "");
    for (const auto& [level, methods] : sc["methods"].items()) {
      for (const auto& [method, e] : methods.items()) row(level.substr(5), method, e, fmt(e["seconds"].get<double>(), 1));
    }
  }
  return md.str();
}

}  // namespace haarcast::app
