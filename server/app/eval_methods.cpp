#include "eval_methods.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <sstream>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/cpu/reference.h"
#include "haarcast/render/renderer.h"
#include "loadtest_storage.h"
#include "number_format.h"
#include "truth_metrics.h"

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Probe {
  std::string name;
  render::Environment environment;
};

Probe rankingProbe(const EvalOptions& o, std::vector<std::string>& notes) {
  const fs::path data(o.dataDir);
  auto have = [&](const char* p) { return !o.dataDir.empty() && fs::is_regular_file(data / p); };
  if (!o.quick && have("probes/adams_place_bridge_1k.hdr")) {
    return {"adams_place_bridge_1k", render::environmentFromFile((data / "probes/adams_place_bridge_1k.hdr").string())};
  }
  if (have("probes/grace_latlong_256x128.hdr")) {
    return {"grace_latlong_256x128", render::environmentFromFile((data / "probes/grace_latlong_256x128.hdr").string())};
  }
  notes.push_back("no probes in the data folder: the methods are ranked under the built-in sky");
  return {"builtin-sky", render::builtinEnvironment()};
}

// The sphere of docs/scenes/mirror-ggx.json: the built-in sphere, seen a
// little from above.
render::Scene rankingScene(const render::Environment& environment, const std::string& material) {
  render::Scene s;
  s.environment = environment;
  s.objects.push_back({"ball", std::make_shared<Mesh>(assets::makeSphere(48)), render::materialFromSpec(material), {}});
  s.camera.eye = {0.0, 0.3, 3.0};
  s.camera.target = {0.0, 0.0, 0.0};
  s.camera.fovYDegrees = 40.0;
  return s;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace

nlohmann::json runMethodRanking(const TruthRun& run, std::vector<std::string>& notes) {
  const EvalOptions& o = run.options;
  const int frame = o.methodsFrame > 0 ? o.methodsFrame : (o.quick ? 16 : 64);
  const int level = o.methodsLevel > 0 ? o.methodsLevel : (o.quick ? 4 : 5);
  const int frames = o.quick ? 2 : 5;
  const Probe probe = rankingProbe(o, notes);
  const render::ReferenceOptions ro = truthReferenceOptions(run, frame, o.quick ? 0.05 : 0.003, o.quick ? 256 : 16384, true);
  // The product's defaults, as `render` draws, one sample per pixel.
  render::RenderOptions defaults;
  defaults.width = defaults.height = frame;
  defaults.level = level;
  defaults.environmentBackground = false;
  defaults.antialias = false;
  defaults.cacheDir = run.base.cacheDir;
  defaults.threads = run.base.threads;

  nlohmann::json out;
  out["config"] = {{"probe", probe.name},
                   {"model", "the built-in sphere (48 segments)"},
                   {"frame", frame},
                   {"level", level},
                   {"frames_timed", frames},
                   {"tolerance", ro.tolerance},
                   {"max_samples", ro.maxSamples},
                   {"light_coefficients", defaults.lightCoefficients},
                   {"theta_samples", defaults.thetaSamples}};
  for (const RotationMethod m : kRankedMethods) out["config"]["methods"].push_back(methodName(m));
  const StageProgress inner = run.progress.callback();
  const std::vector<RankedMaterial> materials = rankedMaterials();
  // Storage does not depend on the material (T slices of one level, or T
  // lobes): sized once per method, from the first material's slice table.
  std::map<RotationMethod, std::size_t> storedBytes;
  for (const RankedMaterial& material : materials) {
    const render::Scene scene = rankingScene(probe.environment, material.spec);
    const std::string stage = "eval methods ranked " + material.spec;
    nlohmann::json& js = out["materials"][material.spec];
    js["role"] = material.role;
    render::ReferenceOptions a = ro;
    a.seed = 1;
    const render::ReferenceResult truth = monteCarlo(run, scene, a, stage + ": Monte Carlo");
    render::ReferenceOptions b = ro;
    b.seed = 2;
    b.tolerance = 0.0;
    b.maxSamples = truth.samples;
    const render::ReferenceResult second = monteCarlo(run, scene, b, stage + ": second truth");
    const TruthError floor = compareWithTruth(truth.image.rgb, second.image.rgb, truth.objectMask, {});
    js["mc"] = {{"samples", truth.samples}, {"half_error", truth.halfError}, {"seconds", truth.seconds}};
    js["floor"] = {{"psnr", floor.psnr}, {"relative_l2", floor.relativeL2}, {"brightness", floor.brightness}};
    run.log("methods ranked " + material.spec + ": truth " + std::to_string(truth.samples) + " samples, half error " +
            fmt(truth.halfError, 4) + "; floor " + fmt(floor.psnr) + " dB, relative L2 " + fmt(floor.relativeL2, 4));

    const std::size_t renders = std::size(kRankedMethods);
    std::size_t rendered = 0;
    run.progress.update(stage + ": methods", 0, renders);
    std::vector<double> seconds, bytes, l2;
    for (const RotationMethod method : kRankedMethods) {
      render::RenderOptions opt = defaults;
      opt.method = method;
      const auto t0 = Clock::now();
      const std::unique_ptr<render::Renderer> renderer = render::makeCpuRenderer(scene, opt, inner);
      const double precompute = since(t0);
      render::FrameRequest request;
      request.width = request.height = frame;
      request.camera = scene.camera;
      render::Frame last = renderer->render(request);  // the warm-up
      std::vector<double> times;
      for (int f = 0; f < frames; ++f) {
        last = renderer->render(request);
        times.push_back(last.seconds);
      }
      const TruthError e = compareWithTruth(truth.image.rgb, last.image.rgb, truth.objectMask, {});
      if (!storedBytes.count(method)) {
        storedBytes[method] =
            methodStoredBytes(method, {render::objectSliceTable(scene.objects.front(), opt, inner)}, opt.rotator);
      }
      const std::size_t stored = storedBytes[method];
      nlohmann::json j = toJson(e);
      j["frame_seconds"] = median(times);
      j["precompute_seconds"] = precompute;
      j["stored_bytes"] = stored;
      j["coefficient_bytes_per_frame"] = last.coefficientBytes;
      js["methods"][std::string(methodName(method))] = std::move(j);
      seconds.push_back(median(times));
      bytes.push_back(static_cast<double>(stored));
      l2.push_back(e.relativeL2);
      run.log("methods ranked " + material.spec + " " + std::string(methodName(method)) + ": " + fmt(1e3 * median(times)) +
              " ms a frame, " + bytesText(static_cast<double>(stored)) + ", " + fmt(e.psnr) + " dB, relative L2 " +
              fmt(e.relativeL2, 4) + ", brightness " + fmt(e.brightness, 4));
      run.progress.update(stage + ": methods", ++rendered, renders);
    }
    const std::vector<int> speed = ranksAscending(seconds), storage = ranksAscending(bytes), closeness = ranksAscending(l2);
    for (std::size_t i = 0; i < std::size(kRankedMethods); ++i) {
      js["methods"][std::string(methodName(kRankedMethods[i]))]["rank"] = {
          {"speed", speed[i]}, {"storage", storage[i]}, {"truth", closeness[i]}};
    }
  }
  // The summary: each criterion's rank averaged over the materials.
  for (const RotationMethod m : kRankedMethods) {
    const std::string name(methodName(m));
    double speed = 0.0, storage = 0.0, closeness = 0.0;
    for (const RankedMaterial& material : materials) {
      const auto& r = out["materials"][material.spec]["methods"][name]["rank"];
      speed += r["speed"].get<double>();
      storage += r["storage"].get<double>();
      closeness += r["truth"].get<double>();
    }
    const double n = static_cast<double>(materials.size());
    out["summary"][name] = {{"speed", speed / n}, {"storage", storage / n}, {"truth", closeness / n}};
  }
  return out;
}

}  // namespace haarcast::app
