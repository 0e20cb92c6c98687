#include "render_command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <unistd.h>

#include "haarcast/io/image.h"
#include "haarcast/io/mesh_io.h"
#include "haarcast/render/cpu_renderer.h"
#include "haarcast/render/scene.h"
#include "plots.h"

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;

struct RenderArgs {
  std::string scene, env, mesh, material = "phong:64", layout = "auto";
  std::vector<double> rotate;
  std::string method = "haar", variant = "refined", background = "env", backend = "cpu";
  std::string out = "render.exr", cacheDir;
  std::optional<double> exposure;
  render::RenderOptions options;
};

std::string defaultCacheDir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return (fs::path(xdg) / "haarcast").string();
  if (const char* home = std::getenv("HOME"); home && *home) return (fs::path(home) / ".cache" / "haarcast").string();
  return ".haarcast-cache";
}

// One line per stage, redrawn in place on a terminal: "[visibility bunny]
// 42% (15000/35947)"; in a log only the start and the end of each stage.
void showProgress(const std::string& stage, std::size_t done, std::size_t total) {
  static const bool terminal = isatty(fileno(stderr)) != 0;
  static std::string last;
  static int lastPercent = -1;
  const int percent = total ? static_cast<int>(100 * done / total) : 100;
  if (stage == last && percent == lastPercent) return;
  if (!terminal) {
    if (stage != last) std::fprintf(stderr, "[%s] started (%zu items)\n", stage.c_str(), total);
    if (done >= total) std::fprintf(stderr, "[%s] done\n", stage.c_str());
    last = done >= total ? std::string() : stage;
    lastPercent = percent;
    return;
  }
  if (stage != last && !last.empty()) std::fputc('\n', stderr);
  std::fprintf(stderr, "\r[%s] %3d%% (%zu/%zu)", stage.c_str(), percent, done, total);
  if (done >= total) std::fputc('\n', stderr);
  std::fflush(stderr);
  last = done >= total ? std::string() : stage;
  lastPercent = percent;
}

int run(RenderArgs& a) {
  if (a.backend != "cpu") throw std::invalid_argument("--backend " + a.backend + " is not available yet (cpu only)");
  const auto method = parseRotationMethod(a.method);
  if (!method) throw std::invalid_argument("--method must be haar, spatial, matrix or table (got \"" + a.method + "\")");
  const auto variant = parseHaarVariant(a.variant);
  if (!variant) throw std::invalid_argument("--haar-variant must be faithful, local or refined (got \"" + a.variant + "\")");
  if (a.background != "env" && a.background != "black") throw std::invalid_argument("--background must be env or black");
  a.options.method = *method;
  a.options.rotator.haarVariant = *variant;
  a.options.environmentBackground = a.background == "env";
  a.options.cacheDir = a.cacheDir.empty() ? defaultCacheDir() : (a.cacheDir == "none" ? "" : a.cacheDir);

  render::Scene scene;
  if (!a.scene.empty()) {
    if (!a.mesh.empty() || !a.env.empty()) throw std::invalid_argument("give either --scene or --env/--mesh, not both");
    scene = render::loadScene(a.scene);
  } else if (!a.mesh.empty()) {
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
  } else {
    if (!a.env.empty()) throw std::invalid_argument("--env needs --mesh (or use --scene)");
    scene = render::defaultScene();
  }

  for (const auto& object : scene.objects) {
    if (!object.material.warning.empty()) std::fprintf(stderr, "warning: %s\n", object.material.warning.c_str());
  }
  const auto t0 = std::chrono::steady_clock::now();
  const render::RenderResult r = render::renderCpu(scene, a.options, showProgress);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // Without --exposure: Reinhard's key (log-average luminance → 0.18).
  const double exposure = a.exposure ? *a.exposure : reinhardKeyExposure(r.image);

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
  std::fprintf(stderr,
               "%d×%d, level %d, %s, k = %zu: %.2f s (precompute %.2f, light %.3f, G-buffer %.3f, shading %.2f)\n",
               a.options.width, a.options.height, a.options.level, a.method.c_str(), a.options.lightCoefficients,
               seconds, r.timings.precompute, r.timings.light, r.timings.gbuffer, r.timings.shading);
  return 0;
}

}  // namespace

std::function<int()> addRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* c = app.add_subcommand("render", "Render a scene on the CPU backend (linear EXR + tonemapped PNG)");
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
  c->add_option("--method", args->method, "Rotation method: haar|spatial|matrix|table")->capture_default_str();
  c->add_option("--haar-variant", args->variant, "faithful|local|refined")->capture_default_str();
  c->add_option("--level", args->options.level, "Map level n (M = 2^n)")->capture_default_str();
  c->add_option("--light-coeffs", args->options.lightCoefficients, "Light coefficients kept (k)")
      ->capture_default_str();
  c->add_option("--visibility-coeffs", args->options.visibility.keep, "Visibility coefficients kept per vertex")
      ->capture_default_str();
  c->add_option("--backend", args->backend, "cpu (vulkan arrives with step 3)")->capture_default_str();
  c->add_option("--out", args->out, "Output .exr (a .png is written beside it) or .png")->capture_default_str();
  c->add_option("--exposure", args->exposure, "PNG exposure in stops (default: log-average luminance → 0.18)");
  c->add_option("--cache-dir", args->cacheDir, "Cache of slice tables and visibility (default $XDG_CACHE_HOME/haarcast; 'none' disables)");
  c->add_option("--threads", args->options.threads, "Worker threads (0 = all cores)")->capture_default_str();
  return [c, args]() { return c->parsed() ? run(*args) : -1; };
}

}  // namespace haarcast::app
