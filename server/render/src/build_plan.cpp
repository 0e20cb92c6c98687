#include "haarcast/render/build_plan.h"

#include <filesystem>
#include <system_error>

#include "haarcast/io/slice_cache.h"
#include "haarcast/render/backend_names.h"
#include "haarcast/render/object_levels.h"
#include "haarcast/render/visibility_refine.h"

namespace haarcast::render {
namespace {

// The cost model, in seconds on the reference machine (2 cores, Embree on
// AVX-512), fitted to `haarcast serve --cache-dir none` builds of the
// Stanford bunny in Grace (fused, level 6: its MERL slice table in about
// 0.25 s, the visibility of its 71,894 refined vertices in 6.8 s). A slice
// table evaluates the BRDF T·4ⁿ·s² times (θₒ samples, map pixels,
// supersamples); visibility casts 4ⁿ·s² rays per vertex (the refined
// ones: the refinement's vertex budget, which its rounds may stop short of).
// Rays cost more among a mesh's own folds than off a convex one, and
// analytic BRDFs less than tabulated ones: the fraction is a fair weight,
// not a clock, and the time left scales it by the rates this build measures.
constexpr double kSecondsPerBrdfSample = 1.5e-7;
constexpr double kSecondsPerVisibilityRay = 5.8e-9;
constexpr double kRotatorShareOfSlices = 1.0;
constexpr double kLightRotatorShareOfSlices = 0.05;
// A slice table read from the cache: its bytes decoded, a hundredth of
// the BRDF samples that made them. A further Vulkan frame slot, and the
// Vulkan warm-up frame (lavapipe compiles its shaders then).
constexpr double kCachedSliceShare = 0.01;
constexpr double kFrameSlotSeconds = 0.5;
constexpr double kWarmUpSeconds = 8.0;

double pixels(int level) { return static_cast<double>(std::size_t{1} << (2 * level)); }

bool sliceTableCached(const SceneObject& object, const RenderOptions& options, int level) {
  if (options.cacheDir.empty() || object.material.cacheKey.empty()) return false;
  SliceTableOptions table;
  table.level = level;
  table.thetaSamples = options.thetaSamples;
  table.supersampling = options.sliceSupersampling;
  std::error_code ec;
  return std::filesystem::is_regular_file(
      std::filesystem::path(options.cacheDir) / io::sliceCacheFileName(object.material.cacheKey, table), ec);
}

}  // namespace

double BuildPlan::totalWork() const {
  double total = 0.0;
  for (const PlannedStage& s : stages) total += s.work;
  return total;
}

BuildPlan planBuild(const Scene& scene, const RenderOptions& options, std::string_view backend) {
  BuildPlan plan;
  const bool fused = options.method == RotationMethod::Fused;
  const bool splitsum = options.method == RotationMethod::Splitsum;
  const std::vector<ObjectPlan> levels = planObjects(scene, options);
  const double supersamples = static_cast<double>(options.sliceSupersampling) * options.sliceSupersampling;
  const double rays = static_cast<double>(options.visibility.supersampling) * options.visibility.supersampling;
  std::vector<double> sliceWork(scene.objects.size(), 0.0);
  // prepareScene: per object, its slice table, then its visibility.
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    const SceneObject& object = scene.objects[k];
    const int level = levels[k].level;
    if (splitsum) continue;  // its lobes are all it computes: no stage reported
    sliceWork[k] = static_cast<double>(options.thetaSamples) * pixels(level) * supersamples * kSecondsPerBrdfSample;
    plan.stages.push_back({"slices " + object.name, sliceWork[k] * (sliceTableCached(object, options, level) ? kCachedSliceShare : 1.0)});
    std::size_t vertices = object.mesh->positions.size();
    if (fused && !object.ground && options.refine.rounds > 0) vertices = refineVertexBudget(vertices, options.refine);
    plan.stages.push_back({"visibility " + object.name,
                           static_cast<double>(vertices) * pixels(level) * rays * kSecondsPerVisibilityRay});
  }
  // fused: the point lights' finer tables, where a lobe needs one (an
  // environment without point lights skips them, and the fraction jumps).
  for (std::size_t k = 0; fused && k < scene.objects.size(); ++k) {
    const SceneObject& object = scene.objects[k];
    const int level = pointLightLevel(levels[k].lobes, levels[k].level);
    if (object.ground || level == levels[k].level) continue;
    const double work = static_cast<double>(options.thetaSamples) * pixels(level) * supersamples * kSecondsPerBrdfSample;
    plan.stages.push_back({std::string(kPointSlicesStage) + " " + object.name,
                           work * (sliceTableCached(object, options, level) ? kCachedSliceShare : 1.0)});
  }
  if (backend == kCpuBackend && !fused && !splitsum) {
    // The CPU renderer's rotators, after prepareScene (cpu_backend.cpp).
    const bool heavy = options.method == RotationMethod::Matrix || options.method == RotationMethod::Table;
    for (std::size_t k = 0; k < scene.objects.size(); ++k) {
      plan.stages.push_back({"rotators " + scene.objects[k].name,
                             sliceWork[k] * (heavy ? kRotatorShareOfSlices : kLightRotatorShareOfSlices)});
    }
  }
  if (backend == kVulkanBackend) {
    plan.stages.push_back({"frame slots", kFrameSlotSeconds});
    plan.stages.push_back({"warm-up", kWarmUpSeconds});
  }
  return plan;
}

}  // namespace haarcast::render
