// A build's plan (build_plan.h) against the build itself: the stages the
// CPU renderer reports through RenderProgress, in the order they first
// appear, are the plan's, for every method and with a ground; and the
// work follows the cost model (four times per level, nothing much for a
// slice table in the cache).
#include "haarcast/render/build_plan.h"

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/core/brdf.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/backend_names.h"

namespace haarcast::render {
namespace {

Scene scene() {
  Scene s;
  s.environment = builtinEnvironment();
  s.objects.push_back({"torus", std::make_shared<Mesh>(assets::makeTorus(0.6, 0.25, 16, 8)), materialFromSpec("phong:16"), {}});
  SceneObject ground{"ground", std::make_shared<Mesh>(assets::makePlane(1.0, 2)), materialFromSpec("lambert"), {}};
  ground.ground = true;
  ground.groundAlbedo = glm::dvec3(0.5);
  ground.material.brdf = makeLambert(ground.groundAlbedo);
  ground.material.cacheKey = "lambert-0.5";
  s.objects.push_back(ground);
  s.camera.eye = {0.0, 0.8, 2.6};
  return s;
}

RenderOptions options(RotationMethod method) {
  RenderOptions o;
  o.method = method;
  o.level = 3;
  o.automaticLevel = false;
  o.thetaSamples = 4;
  o.sliceSupersampling = 1;
  o.visibility.supersampling = 1;
  o.lightCoefficients = 16;
  o.refine.rounds = 1;
  o.threads = 2;
  return o;
}

// The stage names in the order the build first reports them.
std::vector<std::string> reportedStages(const Scene& s, const RenderOptions& o) {
  std::vector<std::string> stages;
  makeCpuRenderer(s, o, [&](const std::string& stage, std::size_t, std::size_t) {
    if (std::find(stages.begin(), stages.end(), stage) == stages.end()) stages.push_back(stage);
  });
  return stages;
}

TEST(BuildPlan, TheCpuBuildReportsThePlansStagesInItsOrder) {
  const Scene s = scene();
  for (const RotationMethod method : kAllPixelMethods) {
    const RenderOptions o = options(method);
    const BuildPlan plan = planBuild(s, o, kCpuBackend);
    std::vector<std::string> planned;
    for (const PlannedStage& p : plan.stages) {
      planned.push_back(p.name);
      EXPECT_GT(p.work, 0.0) << methodName(method) << " " << p.name;
    }
    EXPECT_EQ(reportedStages(s, o), planned) << methodName(method);
    // fused under the built-in sun: phong:16's lobe at level 3 needs its
    // point lights' finer table (object_levels.h pointLightLevel).
    if (method == RotationMethod::Fused) {
      EXPECT_NE(std::find(planned.begin(), planned.end(), std::string(kPointSlicesStage) + " torus"), planned.end());
    }
  }
}

TEST(BuildPlan, WorkGrowsFourfoldPerLevelAndACachedSliceTableCostsALoad) {
  const Scene s = scene();
  RenderOptions o = options(RotationMethod::Haar);
  const BuildPlan at3 = planBuild(s, o, kCpuBackend);
  o.level = 4;
  const BuildPlan at4 = planBuild(s, o, kCpuBackend);
  ASSERT_EQ(at3.stages.size(), at4.stages.size());
  for (std::size_t i = 0; i < at3.stages.size(); ++i) EXPECT_NEAR(at4.stages[i].work / at3.stages[i].work, 4.0, 1e-9) << at3.stages[i].name;
  // The torus's table in a cache: its stage is a load's.
  const auto dir = std::filesystem::temp_directory_path() / ("haarcast_plan_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  o.cacheDir = dir.string();
  const double computed = planBuild(s, o, kCpuBackend).stages.front().work;
  (void)objectSliceTable(s.objects.front(), o);
  const BuildPlan cached = planBuild(s, o, kCpuBackend);
  EXPECT_EQ(cached.stages.front().name, "slices torus");
  EXPECT_LT(cached.stages.front().work, computed / 10.0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace haarcast::render
