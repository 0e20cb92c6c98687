// `fused`'s light made on the device (shaders/light.comp, fused_light.cpp)
// against the host's (render::resolveFrame, which the CPU backend shades
// from): each object's light texels L·ΔΩ in its own frame, its cells'
// power and centroids, and the ground's flat radiance, for turned objects
// and a turned light, two frames in a row (the second must not keep the
// first's light).
//
// Why not equal: the host turns and averages the map in double, the device
// in float (directions, taps and sums), so a texel differs by float
// rounding, a few parts in a million of the brightest texel; a texel whose
// centre lies within rounding of the ground's plane could fall on the other
// side of it, which none in these frames does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "frame_compare.h"
#include "gpu_test_util.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/gpu/vulkan_renderer.h"
#include "haarcast/render/renderer.h"

namespace haarcast::gpu {
namespace {

struct LightCase {
  const char* name;
  int level;
  bool automaticLevel;
  float sumTolerance;  // > 0: by cells (levels ≥ shared::kCellMinLevel)
};

void PrintTo(const LightCase& c, std::ostream* os) { *os << c.name; }

class LightPass : public testing::GpuTestWithParam<LightCase> {};

// How far the device's light is from the host's, over every object.
struct LightDiff {
  double texels = 0.0;      // the largest |device − host|, relative to the object's brightest texel
  std::size_t zeroed = 0;   // texels one side zeroes below the ground and the other does not
  double power = 0.0;       // cells: the largest |ΔP|, relative to the object's brightest cell
  double centroid = 0.0;    // cells: the largest angle between the centroids (radians)
  double ground = 0.0;      // the ground's flat radiance, relative
  std::size_t cells = 0;
};

LightDiff diffLight(const VulkanRenderer& gpu, const render::RenderOptions& o, const render::FrameRequest& request) {
  const render::PreparedScene& prepared = gpu.prepared();
  const render::ResolvedFrame host = render::resolveFrame(prepared, o, request);
  const std::vector<glm::vec4> texels = gpu.lightTexels();
  const std::vector<ObjectInfo> infos = gpu.objectInfos();
  LightDiff d;
  EXPECT_EQ(infos.size(), prepared.objects.size());
  for (std::size_t i = 0; i < infos.size(); ++i) {
    const ObjectInfo& info = infos[i];
    const FusedLight& light = host.objects[i].fusedLight;
    const std::size_t m = static_cast<std::size_t>(mapSize(static_cast<int>(info.level))), n = m * m;
    EXPECT_EQ(light.planes.size(), 3 * n) << "object " << i;
    EXPECT_LE(info.lightBase + n, texels.size());
    if (light.planes.size() != 3 * n || info.lightBase + n > texels.size()) continue;
    float brightest = 0.0f;
    for (float v : light.planes) brightest = std::max(brightest, v);
    EXPECT_GT(brightest, 0.0f) << "object " << i << " has no light";
    for (std::size_t k = 0; k < n; ++k) {
      for (std::size_t c = 0; c < 3; ++c) {
        const float h = light.planes[c * n + k], g = texels[info.lightBase + k][static_cast<int>(c)];
        d.texels = std::max(d.texels, std::abs(static_cast<double>(g) - h) / brightest);
        if ((h == 0.0f) != (g == 0.0f)) ++d.zeroed;
      }
    }
    EXPECT_EQ(light.sumsByCells(), info.sumTolerance > 0.0f) << "object " << i;
    if (light.sumsByCells()) {
      const std::size_t cells = n / shared::kCellDirections;
      const CellLight& cl = light.cells;
      float strongest = 0.0f;
      for (std::size_t q = 0; q < cells; ++q)
        for (std::size_t c = 0; c < 3; ++c) strongest = std::max(strongest, cl.power[c * cl.stride + q]);
      for (std::size_t q = 0; q < cells; ++q) {
        const auto mm = static_cast<shared::uint>(m), qq = static_cast<shared::uint>(q);
        const glm::vec4 p = texels[info.lightBase + shared::cellPowerTexel(mm, qq)];
        const glm::vec4 at = texels[info.lightBase + shared::cellCentroidTexel(mm, qq)];
        for (std::size_t c = 0; c < 3; ++c)
          d.power = std::max(d.power, std::abs(static_cast<double>(p[static_cast<int>(c)]) - cl.power[c * cl.stride + q]) / strongest);
        const glm::dvec3 a(at), b(cl.centroidX[q], cl.centroidY[q], cl.centroidZ[q]);
        d.centroid = std::max(d.centroid, std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)));
        ++d.cells;
      }
    }
    if (prepared.objects[i].ground) {
      const std::array<float, 3>& flat = host.objects[i].groundFlat;
      for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_GT(flat[c], 0.0f);
        d.ground = std::max(d.ground, std::abs(static_cast<double>(info.groundRadiance[static_cast<int>(c)]) - flat[c]) / flat[c]);
      }
    }
  }
  return d;
}

// A small frame of the default scene at the case's levels.
render::RenderOptions lightOptions(const LightCase& c) {
  render::RenderOptions o = testing::frameOptions(RotationMethod::Fused, true);
  o.width = 48;
  o.height = 32;
  o.level = c.level;
  o.automaticLevel = c.automaticLevel;
  o.sumTolerance = c.sumTolerance;
  return o;
}

// The device's light within float rounding of the host's (the file's comment).
void expectTheHostsLight(const LightDiff& d) {
  EXPECT_LE(d.texels, 2e-5);
  EXPECT_EQ(d.zeroed, 0u);
  EXPECT_LE(d.power, 1e-5);
  EXPECT_LE(d.centroid, 1e-4);
  EXPECT_LE(d.ground, 1e-5);
}

// The default scene (a sphere and a torus on a ground): the torus and the
// light turned, then the sphere and the light turned otherwise; then the
// same again (no object's light made afresh), the torus alone turned (its
// alone), the light alone (every object's).
TEST_P(LightPass, DeviceMakesTheHostsLight) {
  HAARCAST_REQUIRE_VULKAN();
  const LightCase& c = GetParam();
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = lightOptions(c);
  VulkanRenderer gpu(scene, o, testing::testOptions());
  render::FrameRequest request = testing::requestFor(scene, o.width, o.height);
  request.poses = testing::scenePoses(scene);
  std::vector<render::FrameRequest> requests;
  request.poses[1].rotateDegrees += glm::dvec3(10.0, 25.0, -5.0);
  request.lightRotation = rotationMatrix({0.3, -0.4, 0.1});
  requests.push_back(request);
  request.poses[0].rotateDegrees += glm::dvec3(-30.0, 70.0, 15.0);
  request.lightRotation = rotationMatrix({-1.1, 0.7, 2.0});
  requests.push_back(request);
  requests.push_back(request);
  request.poses[1].rotateDegrees += glm::dvec3(0.0, 40.0, 0.0);
  requests.push_back(request);
  request.lightRotation = rotationMatrix({0.2, 0.1, -0.3});
  requests.push_back(request);
  const std::size_t objects = scene.objects.size();
  const std::vector<std::size_t> made = {objects, objects, 0, 1, objects};  // a turned light turns every object's
  for (std::size_t f = 0; f < requests.size(); ++f) {
    const render::FrameRequest& r = requests[f];
    const render::Frame frame = gpu.render(r);
    ASSERT_FALSE(frame.cancelled);
    EXPECT_EQ(gpu.lightsMadeLastFrame(), made[f]) << "frame " << f;
    const LightDiff d = diffLight(gpu, o, r);
    std::printf("%s: texels off by %.2e of the brightest, %zu zeroed on one side only; %zu cells, power off by %.2e, "
                "centroids by %.2e rad; ground %.2e\n",
                c.name, d.texels, d.zeroed, d.cells, d.power, d.centroid, d.ground);
    expectTheHostsLight(d);
    if (c.sumTolerance > 0.0f) {
      EXPECT_GT(d.cells, 0u);
    }
  }
  testing::expectNoValidationMessages(gpu.context());
}

// A frame stopped after its light stage (a CPU device submits stage by
// stage and polls between them) leaves the buffer with its light while the
// light's record still names the frame before: the next frame, turned as
// that one, must make its light again rather than keep the stopped frame's.
TEST_P(LightPass, AStoppedFrameLeavesNoLightBehind) {
  HAARCAST_REQUIRE_VULKAN();
  const LightCase& c = GetParam();
  const render::Scene scene = render::defaultScene();
  const render::RenderOptions o = lightOptions(c);
  VulkanRenderer gpu(scene, o, testing::testOptions());
  render::FrameRequest first = testing::requestFor(scene, o.width, o.height);
  first.poses = testing::scenePoses(scene);
  render::FrameRequest turned = first;
  turned.poses[0].rotateDegrees += glm::dvec3(20.0, -60.0, 5.0);
  turned.lightRotation = rotationMatrix({0.9, -0.2, 0.4});
  gpu.render(first);
  int polls = 0;
  turned.cancelled = [&] { return ++polls >= 2; };  // after the first stage
  const render::Frame stopped = gpu.render(turned);
  if (stopped.cancelled) {
    ASSERT_FALSE(stopped.stages.empty());
    EXPECT_EQ(stopped.stages.front().name, "light");
  }  // else the device took the frame in one submission, polled once before it
  const render::Frame again = gpu.render(first);
  ASSERT_FALSE(again.cancelled);
  SCOPED_TRACE("the stopped frame's light must not be kept");
  expectTheHostsLight(diffLight(gpu, o, first));
  testing::expectNoValidationMessages(gpu.context());
}

INSTANTIATE_TEST_SUITE_P(Cases, LightPass,
                         ::testing::Values(LightCase{"level4", 4, false, 0.0f},
                                           LightCase{"auto6_cells", 6, true, 0.1f}),
                         [](const ::testing::TestParamInfo<LightCase>& param) { return std::string(param.param.name); });

}  // namespace
}  // namespace haarcast::gpu
