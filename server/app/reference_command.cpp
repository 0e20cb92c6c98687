// `haarcast reference`: the Monte Carlo truth of what `haarcast render` draws,
// with render's scene flags, converged until its two half-images agree.
#include "reference_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "haarcast/io/image.h"
#include "haarcast/io/mesh_io.h"
#include "haarcast/render/reference.h"
#include "haarcast/render/scene.h"

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;

struct ReferenceArgs {
  std::string scene, env, mesh, material = "phong:64", layout = "auto";
  std::vector<double> rotate;
  std::string background = "env", sampling = "mis", out = "reference.exr";
  std::optional<double> exposure;
  render::ReferenceOptions options;
};

// The scene `haarcast render` builds from the same flags (render_command.cpp;
// to be shared once both commands settle).
render::Scene sceneFromFlags(const ReferenceArgs& a) {
  render::Scene scene;
  if (!a.scene.empty()) {
    if (!a.mesh.empty() || !a.env.empty()) throw std::invalid_argument("give either --scene or --env/--mesh, not both");
    return render::loadScene(a.scene);
  }
  if (a.mesh.empty()) {
    if (!a.env.empty()) throw std::invalid_argument("--env needs --mesh (or use --scene)");
    return render::defaultScene();
  }
  scene = render::defaultScene();
  scene.objects.clear();
  if (!a.env.empty()) scene.environment = render::environmentFromFile(a.env, a.layout);
  auto mesh = std::make_shared<Mesh>(io::loadMesh(a.mesh));
  render::fitToUnitSphere(*mesh);
  render::SceneObject object{fs::path(a.mesh).stem().string(), mesh, render::materialFromSpec(a.material), {}};
  if (!a.rotate.empty()) {
    if (a.rotate.size() != 3) throw std::invalid_argument("--rotate takes X,Y,Z in degrees");
    object.pose.rotateDegrees = {a.rotate[0], a.rotate[1], a.rotate[2]};
  }
  scene.objects.push_back(object);
  scene.camera.eye = {0.0, 0.3, 3.0};
  return scene;
}

int run(ReferenceArgs& a) {
  if (a.background != "env" && a.background != "black") throw std::invalid_argument("--background must be env or black");
  const auto sampling = render::parseReferenceSampling(a.sampling);
  if (!sampling) {
    throw std::invalid_argument("--sampling must be mis, mis-cosine, environment, brdf or cosine (got \"" + a.sampling + "\")");
  }
  a.options.environmentBackground = a.background == "env";
  a.options.sampling = *sampling;
  render::checkReferenceOptions(a.options);
  const render::Scene scene = sceneFromFlags(a);

  // Progress at most once a second (a pair of passes can take milliseconds).
  auto last = std::chrono::steady_clock::now();
  const render::ReferenceResult r = render::renderReference(scene, a.options, [&last](int samples, double error) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last < std::chrono::seconds(1)) return;
    last = now;
    std::fprintf(stderr, "[reference] %d samples/pixel, half-image difference %.4f\n", samples, error);
    std::fflush(stderr);
  });

  // Without --exposure: Reinhard's key, as `render` (log-average luminance → 0.18).
  double exposure = 0.0;
  if (a.exposure) {
    exposure = *a.exposure;
  } else {
    double sumLog = 0.0;
    const std::size_t n = r.image.rgb.size() / 3;
    for (std::size_t i = 0; i < n; ++i) {
      const double y = 0.2126 * r.image.rgb[3 * i] + 0.7152 * r.image.rgb[3 * i + 1] + 0.0722 * r.image.rgb[3 * i + 2];
      sumLog += std::log(1e-4 + std::max(y, 0.0));
    }
    exposure = std::log2(0.18 / std::exp(sumLog / static_cast<double>(n)));
  }

  const fs::path out(a.out);
  const std::string ext = out.extension().string();
  if (ext == ".exr") {
    io::writeExr(out.string(), r.image);
    fs::path png = out;
    io::writePng(png.replace_extension(".png").string(), r.image, exposure);
    std::fprintf(stderr, "wrote %s and %s\n", out.c_str(), png.c_str());
  } else if (ext == ".png") {
    io::writePng(out.string(), r.image, exposure);
    std::fprintf(stderr, "wrote %s\n", out.c_str());
  } else {
    throw std::invalid_argument("--out must end in .exr or .png (got \"" + a.out + "\")");
  }
  std::fprintf(stderr, "%d×%d, %s: %d samples/pixel, half-image difference %.4f (tolerance %.4f), %.2f s\n",
               a.options.width, a.options.height, a.sampling.c_str(), r.samples, r.halfError, a.options.tolerance,
               r.seconds);
  return 0;
}

}  // namespace

std::function<int()> addReferenceCommand(CLI::App& app) {
  auto args = std::make_shared<ReferenceArgs>();
  auto* c = app.add_subcommand("reference", "Monte Carlo reference (Embree) of what `render` draws: the truth for PSNR");
  c->add_option("--scene", args->scene, "Scene file (JSON); see docs/scenes.md");
  c->add_option("--env", args->env, "Environment: EXR, HDR or PFM light probe (lat-long or angular)");
  c->add_option("--env-layout", args->layout, "auto|latlong|angular")->capture_default_str();
  c->add_option("--mesh", args->mesh, "OBJ or PLY mesh (centred and scaled to unit radius)");
  c->add_option("--material", args->material, "lambert, phong:EXP, blinn-phong:EXP, ggx:ROUGHNESS or a MERL .binary")
      ->capture_default_str();
  c->add_option("--rotate", args->rotate, "Object rotation X,Y,Z in degrees")->delimiter(',')->expected(3);
  c->add_option("--width", args->options.width, "Image width")->capture_default_str();
  c->add_option("--height", args->options.height, "Image height")->capture_default_str();
  c->add_option("--background", args->background, "env|black")->capture_default_str();
  c->add_option("--out", args->out, "Output .exr (a .png is written beside it) or .png")->capture_default_str();
  c->add_option("--exposure", args->exposure, "PNG exposure in stops (default: log-average luminance → 0.18)");
  c->add_option("--tolerance", args->options.tolerance,
                "Stop when the half-images' relative RMS difference is at most this (0 = run to --max-samples)")
      ->capture_default_str();
  c->add_option("--max-samples", args->options.maxSamples, "Most samples per pixel")->capture_default_str();
  c->add_option("--samples-per-pass", args->options.samplesPerPass, "Samples per pixel per pass")->capture_default_str();
  c->add_option("--sampling", args->sampling, "mis|mis-cosine|environment|brdf|cosine")->capture_default_str();
  c->add_option("--seed", args->options.seed, "Random seed")->capture_default_str();
  c->add_option("--threads", args->options.threads, "Worker threads (0 = all cores)")->capture_default_str();
  return [c, args]() { return c->parsed() ? run(*args) : -1; };
}

}  // namespace haarcast::app
