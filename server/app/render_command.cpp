#include "render_command.h"
#include "list_flags.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "haarcast/backends/backends.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/shared_smooth.h"
#include "haarcast/render/object_levels.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"
#include "progress.h"
#include "app_paths.h"
#include "scene_flags.h"

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;

struct RenderArgs {
  SceneFlags scene;
  std::string method = "fused", variant = "refined", backend{render::kCpuBackend}, device, cacheDir, antialias = "auto";
  std::string rays = "auto";
  std::string level = "auto";  // render::parseLevelChoice
  bool validation = backends::kValidationByDefault;
  render::RenderOptions options;
};

int run(RenderArgs& a) {
  backends::checkBuilt(a.backend, "--backend");
  if (a.backend == render::kCpuBackend && !a.device.empty()) throw std::invalid_argument("--device applies to --backend vulkan only");
  const render::RayMode rays = parseRayModeFlag(a.rays);
  if (a.backend == render::kCpuBackend && rays == render::RayMode::Device)
    throw std::invalid_argument("--rays device applies to --backend vulkan only (the CPU backend traces on the host)");
  const auto method = parseRotationMethod(a.method);
  if (!method) throw std::invalid_argument("--method must be one of " + pixelMethodNames() + " (got \"" + a.method + "\")");
  const auto variant = parseHaarVariant(a.variant);
  if (!variant) throw std::invalid_argument("--haar-variant must be faithful, local or refined (got \"" + a.variant + "\")");
  a.options.method = *method;
  a.options.rotator.haarVariant = *variant;
  const auto level = render::parseLevelChoice(a.level);
  if (!level) throw std::invalid_argument("--level must be " + render::levelChoiceHelp() + " (got \"" + a.level + "\")");
  render::applyLevelChoice(a.options, *level);
  a.options.width = a.scene.width;
  a.options.height = a.scene.height;
  a.options.environmentBackground = environmentBackground(a.scene);
  a.options.antialias = antialiasFor(a.antialias, a.backend);
  a.options.cacheDir = cacheDirFromFlag(a.cacheDir);
  a.options.sceneLimits = a.scene.limits;
  render::checkRenderOptions(a.options);
  checkOutputPath(a.scene);

  const render::Scene scene = sceneFromFlags(a.scene);
  for (const auto& object : scene.objects) {
    if (!object.material.warning.empty()) std::fprintf(stderr, "warning: %s\n", object.material.warning.c_str());
  }
  // One renderer behind the shared interface: the same scene, request and
  // outputs whichever backend draws them.
  const auto t0 = std::chrono::steady_clock::now();
  StderrProgress progress;  // slice tables and visibility: percentage and time left
  const std::unique_ptr<render::Renderer> renderer =
      backends::makeRenderer(a.backend, scene, a.options, {a.device, a.validation, 0, rays}, progress.callback());
  const double prepare = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  render::FrameRequest request;
  request.width = a.options.width;
  request.height = a.options.height;
  request.camera = scene.camera;  // poses: empty = the scene's own
  const render::Frame frame = renderer->render(request);
  writeOutputImages(a.scene, frame.image, frame.objectMask);
  std::string stages;
  for (const render::StageTime& s : frame.stages) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%s%s %.3f", stages.empty() ? "" : ", ", s.name.c_str(), s.seconds);
    stages += buf;
  }
  // Each object's level (object_levels.h), named, when they differ.
  std::vector<int> levels = renderer->objectLevels();
  if (levels.empty()) levels.assign(renderer->objectCount(), a.options.level);
  std::string levelText = render::describeLevels(levels);
  if (render::levelsInUse(levels).size() > 1) {
    levelText += " (";
    for (std::size_t k = 0; k < levels.size(); ++k)
      levelText += (k ? ", " : "") + scene.objects[k].name + " " + std::to_string(levels[k]);
    levelText += ")";
  }
  if (a.options.automaticLevel) levelText += " [" + level->name() + "]";
  // Objects whose point lights read a finer table (object_levels.h pointLightLevel).
  const std::vector<int> pointLevels = renderer->pointLightLevels();
  std::string finer;
  for (std::size_t k = 0; k < pointLevels.size() && k < levels.size(); ++k) {
    if (pointLevels[k] > levels[k]) finer += (finer.empty() ? "" : ", ") + scene.objects[k].name + " " + std::to_string(pointLevels[k]);
  }
  if (!finer.empty()) levelText += ", point lights' slices at " + finer;
  // What fused's pass summed a sample (render::Frame::passDirections): by
  // cells where a tolerance is set (core/shared_cells.h), else every direction.
  if (frame.passSamples > 0) {
    char sum[96];
    std::snprintf(sum, sizeof sum, ", %.0f directions a sample", static_cast<double>(frame.passDirections) / frame.passSamples);
    levelText += sum;
    if (a.options.sumTolerance > 0.0f) {
      std::snprintf(sum, sizeof sum, " (by cells, τ %g)", static_cast<double>(a.options.sumTolerance));
      levelText += sum;
    }
    if (frame.smoothSamples > 0) {
      std::snprintf(sum, sizeof sum, ", %.0f %% of them from their neighbours (ε %g)",
                    100.0 * static_cast<double>(frame.smoothSamples) / static_cast<double>(frame.passSamples),
                    static_cast<double>(a.options.smoothSumTolerance));
      levelText += sum;
    }
  }
  // How each object's pixels were drawn: its level and what a pixel may
  // spend there, one decision (object_levels.h planObjects).
  const std::vector<std::string> plans = renderer->objectPlans();
  if (!plans.empty()) {
    std::string planText;
    for (std::size_t k = 0; k < plans.size() && k < scene.objects.size(); ++k)
      planText += (k ? "; " : "") + scene.objects[k].name + ": " + plans[k];
    std::fprintf(stderr, "plan: %s\n", planText.c_str());
  }
  std::fprintf(stderr, "%s on %s: %d×%d, %s, %s, k = %zu, rays %s: precompute %.2f s, frame %.3f s (%s)\n",
               renderer->backend().c_str(), renderer->deviceName().c_str(), a.options.width, a.options.height,
               levelText.c_str(), a.method.c_str(), a.options.lightCoefficients, renderer->rays().c_str(), prepare,
               frame.seconds, stages.c_str());
  return 0;
}

}  // namespace

std::function<int()> addRenderCommand(CLI::App& app) {
  auto args = std::make_shared<RenderArgs>();
  auto* c = app.add_subcommand("render", "Render a scene on the CPU or Vulkan backend (linear EXR + tonemapped PNG)");
  args->scene.out = "render.exr";
  addSceneFlags(*c, args->scene);
  c->add_option("--method", args->method, "Per-pixel method: " + pixelMethodNames())->capture_default_str();
  c->add_option("--haar-variant", args->variant, "faithful|local|refined")->capture_default_str();
  c->add_option("--level", args->level, "Map level n (M = 2^n): " + render::levelChoiceHelp())->capture_default_str();
  c->add_option("--light-coeffs", args->options.lightCoefficients, "Light coefficients kept (k)")
      ->capture_default_str();
  c->add_option("--visibility-coeffs", args->options.visibility.keep, "Visibility coefficients kept per vertex")
      ->capture_default_str();
  c->add_option("--visibility-refine", args->options.refine.rounds,
                "fused: rounds of refining the mesh where its vertices' visibility disagrees (0 = off)")
      ->capture_default_str()
      ->check(CLI::Range(0, 16));
  c->add_option("--object-sky", args->options.objectSky,
                "fused: objects hide sky from each other (true|false; false: each meets its own visibility alone)")
      ->capture_default_str();
  args->options.sumTolerance = shared::kDefaultSumTolerance;  // RenderOptions keeps 0, as for automaticLevel
  c->add_option("--sum-tolerance", args->options.sumTolerance,
                sumToleranceHelp())
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  args->options.smoothSumTolerance = shared::kDefaultSmoothSumTolerance;
  c->add_option("--smooth-sum", args->options.smoothSumTolerance, smoothSumHelp())
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--backend", args->backend, "The backend: " + backends::availableText())->capture_default_str();
  c->add_option("--antialias", args->antialias, "auto|on|off: edge pixels as the mean of 4 sub-samples (auto: on)")
      ->capture_default_str();
  c->add_option("--device", args->device, "Vulkan device: an index or a name substring (default: discrete > integrated > CPU)");
  c->add_option("--rays", args->rays, rayModeHelp())->capture_default_str();
  c->add_flag("--validation,!--no-validation", args->validation, "Vulkan validation layers (when installed)")
      ->capture_default_str();
  c->add_option("--cache-dir", args->cacheDir, "Cache of slice tables and visibility (default $XDG_CACHE_HOME/haarcast; 'none' disables)");
  c->add_option("--threads", args->options.threads, "Worker threads (0 = all cores)")->capture_default_str();
  return [c, args]() { return c->parsed() ? run(*args) : -1; };
}

}  // namespace haarcast::app
