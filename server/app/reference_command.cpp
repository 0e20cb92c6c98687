// `haarcast reference`: the Monte Carlo truth of what `haarcast render` draws,
// with render's scene flags, converged until its two half-images agree.
#include "reference_command.h"

#include <cstdio>
#include <memory>
#include <stdexcept>
#include <string>

#include "haarcast/cpu/reference.h"
#include "haarcast/render/scene.h"
#include "progress.h"
#include "scene_flags.h"

namespace haarcast::app {
namespace {

struct ReferenceArgs {
  SceneFlags scene;
  std::string sampling = "mis";
  std::string occlusion = "scene";
  render::ReferenceOptions options;
};

int run(ReferenceArgs& a) {
  const auto sampling = render::parseReferenceSampling(a.sampling);
  if (!sampling) {
    throw std::invalid_argument("--sampling must be mis, mis-cosine, environment, brdf or cosine (got \"" + a.sampling + "\")");
  }
  const auto occlusion = render::parseReferenceOcclusion(a.occlusion);
  if (!occlusion) {
    throw std::invalid_argument("--occlusion must be scene, self or none (got \"" + a.occlusion + "\")");
  }
  a.options.occlusion = *occlusion;
  a.options.width = a.scene.width;
  a.options.height = a.scene.height;
  a.options.environmentBackground = environmentBackground(a.scene);
  a.options.sampling = *sampling;
  render::checkReferenceOptions(a.options);
  checkOutputPath(a.scene);
  const render::Scene scene = sceneFromFlags(a.scene);

  // The percentage of the samples it will take to reach the tolerance.
  StderrProgress progress;
  const render::ReferenceResult r = render::renderReference(
      scene, a.options, monteCarloProgress(progress, "reference", a.options.tolerance, a.options.maxSamples));
  progress.finish("reference");

  writeOutputImages(a.scene, r.image, r.objectMask);
  std::fprintf(stderr, "%d×%d, %s, occlusion %s: %d samples/pixel, half-image difference %.4f (tolerance %.4f), %.2f s\n",
               a.options.width, a.options.height, a.sampling.c_str(), a.occlusion.c_str(), r.samples, r.halfError, a.options.tolerance,
               r.seconds);
  return 0;
}

}  // namespace

std::function<int()> addReferenceCommand(CLI::App& app) {
  auto args = std::make_shared<ReferenceArgs>();
  auto* c = app.add_subcommand("reference", "Monte Carlo reference (Embree) of what `render` draws: the truth for PSNR");
  args->scene.out = "reference.exr";
  addSceneFlags(*c, args->scene);
  c->add_option("--tolerance", args->options.tolerance,
                "Stop when the half-images' relative RMS difference is at most this (0 = run to --max-samples)")
      ->capture_default_str();
  c->add_option("--max-samples", args->options.maxSamples, "Most samples per pixel")->capture_default_str();
  c->add_option("--samples-per-pass", args->options.samplesPerPass, "Samples per pixel per pass")->capture_default_str();
  c->add_option("--sampling", args->sampling, "mis|mis-cosine|environment|brdf|cosine")->capture_default_str();
  c->add_option("--occlusion", args->occlusion,
                "What shadows: scene (every object, posed), self (each object alone) or none")
      ->capture_default_str();
  c->add_option("--seed", args->options.seed, "Random seed")->capture_default_str();
  c->add_option("--threads", args->options.threads, "Worker threads (0 = all cores)")->capture_default_str();
  return [c, args]() { return c->parsed() ? run(*args) : -1; };
}

}  // namespace haarcast::app
