// What users see on the Vulkan backend: antialiased edges by the CPU
// backend's rule (core/shared_layout.h) and the exposure chosen on the
// device, each against the CPU backend on the default scene.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include <glm/vec4.hpp>

#include "frame_compare.h"
#include "gpu_test_util.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/gpu/vulkan_renderer.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/render/exposure_meter.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/shading.h"

namespace haarcast::gpu {
namespace {

using testing::compare;
using testing::frameOptions;
using testing::requestFor;

// The request FusedFrame renders: the second object turned, the light too.
render::FrameRequest turnedRequest(const render::Scene& scene, int w, int h) {
  render::FrameRequest request = requestFor(scene, w, h);
  request.poses = testing::scenePoses(scene);
  request.poses[1].rotateDegrees += glm::dvec3(10.0, 25.0, -5.0);
  request.lightRotation = rotationMatrix({0.3, -0.4, 0.1});
  return request;
}

// The CPU backend's primary visibility, traced with Embree as it traces it:
// per pixel the centre's object + 1 (0: none) and the edge word the rule of
// shared_layout.h gives (0, or kEdgeFlag | the covered sub-samples).
struct TracedEdges {
  std::vector<std::uint32_t> centre;
  std::vector<std::uint32_t> word;
};

TracedEdges traceEdges(const render::PreparedScene& prepared, const render::FrameRequest& request) {
  std::vector<Instance> instances;
  for (std::size_t i = 0; i < prepared.objects.size(); ++i) {
    instances.push_back({prepared.objects[i].mesh.get(), glm::mat4(request.poses[i].objectToWorld())});
  }
  const RayScene rays(std::move(instances));
  const render::CameraRays camera(request.camera, request.width, request.height);
  auto id = [&](double px, double py) -> std::uint32_t {
    Ray r;
    r.origin = glm::vec3(camera.origin());
    r.direction = glm::vec3(camera.directionAt(px, py));
    const std::optional<Hit> hit = rays.intersect(r);
    return hit ? hit->object + 1 : 0;
  };
  const int w = request.width, h = request.height;
  TracedEdges t;
  t.centre.resize(static_cast<std::size_t>(w) * h);
  t.word.assign(t.centre.size(), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) t.centre[static_cast<std::size_t>(y) * w + x] = id(x + 0.5, y + 0.5);
  const double o = shared::kSubsampleOffset;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      bool edge = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          edge |= t.centre[static_cast<std::size_t>(std::clamp(y + dy, 0, h - 1)) * w + std::clamp(x + dx, 0, w - 1)] !=
                  t.centre[p];
      if (!edge) continue;
      t.word[p] = shared::kEdgeFlag;
      for (unsigned k = 0; k < shared::kSubsamples; ++k) {
        if (id(x + 0.5 + ((k & 1u) ? o : -o), y + 0.5 + ((k & 2u) ? o : -o))) t.word[p] |= 1u << k;
      }
    }
  }
  return t;
}

// Vulkan fused with antialiasing against the CPU backend's, the frame
// FusedFrame compares: the same edge pixels with the same covered
// sub-samples (up to a few where the rasteriser and Embree split a
// silhouette differently), and the same image on the pixels whose samples
// agree, at the floor of the one-sample frames.
GPU_TEST(Antialias, VulkanMatchesTheCpuBackend) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  o.antialias = true;
  const auto cpu = render::makeCpuRenderer(scene, o);
  VulkanRenderer gpu(scene, o, testing::testOptions());
  const render::FrameRequest request = turnedRequest(scene, o.width, o.height);
  const render::Frame a = cpu->render(request);
  const render::Frame b = gpu.render(request);
  const std::vector<std::uint32_t> words = gpu.edgeWords();
  const TracedEdges traced = traceEdges(gpu.prepared(), request);
  ASSERT_EQ(words.size(), traced.word.size());

  std::size_t gpuEdges = 0, cpuEdges = 0, wordsDiffer = 0;
  render::Frame agreeing = b;  // b where the samples agree, a elsewhere: differences left are shading only
  for (std::size_t p = 0; p < words.size(); ++p) {
    gpuEdges += words[p] != 0;
    cpuEdges += traced.word[p] != 0;
    if (words[p] == traced.word[p]) continue;
    ++wordsDiffer;
    for (std::size_t c = 0; c < 3; ++c) agreeing.image.rgb[3 * p + c] = a.image.rgb[3 * p + c];
  }
  const testing::Comparison c = compare(a, agreeing);
  std::printf("antialiased fused: %zu edge pixels on Vulkan, %zu on the CPU, %zu edge words differ; PSNR %.1f dB "
              "over the rest\n",
              gpuEdges, cpuEdges, wordsDiffer, c.psnr);
  EXPECT_GT(gpuEdges, 100u) << "the default scene has silhouettes";
  EXPECT_LE(std::max(gpuEdges, cpuEdges) - std::min(gpuEdges, cpuEdges), 2u);
  EXPECT_LE(wordsDiffer, 2u + gpuEdges / 50);
  EXPECT_EQ(c.mismatched, 0u);
  EXPECT_GE(c.psnr, testing::fusedPsnrFloor(gpu.context()));
  testing::expectNoValidationMessages(gpu.context());
}

// Antialiasing changes the edge pixels and only them: against the same
// renderer's one-sample frame, interior pixels are bit for bit the same and
// edge pixels centred on an object mostly not (a sub-sample sees another
// object or the backdrop, or another point of a shaded surface). The
// ground's are counted apart: it is flat-shaded (its closed form is the same
// at every lit point), so an edge pixel whose centre and sub-samples all
// fall on it in the same light keeps its value exactly.
GPU_TEST(Antialias, ChangesEdgePixelsOnly) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  VulkanRenderer plain(scene, o, testing::testOptions());
  o.antialias = true;
  VulkanRenderer smooth(scene, o, testing::testOptions());
  const render::FrameRequest request = turnedRequest(scene, o.width, o.height);
  const render::Frame a = plain.render(request);
  const render::Frame b = smooth.render(request);
  const std::vector<std::uint32_t> words = smooth.edgeWords();
  const std::vector<glm::uvec4> ids = smooth.gbufferIds();
  std::uint32_t groundId = 0;  // object + 1, as the G-buffer's ids
  for (std::size_t i = 0; i < scene.objects.size(); ++i)
    if (scene.objects[i].ground) groundId = static_cast<std::uint32_t>(i + 1);
  EXPECT_TRUE(plain.edgeWords().empty());
  std::size_t edges = 0, changed = 0, interiorChanged = 0, groundEdges = 0, groundChanged = 0;
  for (std::size_t p = 0; p < words.size(); ++p) {
    bool differs = false;
    for (std::size_t c = 0; c < 3; ++c) differs |= a.image.rgb[3 * p + c] != b.image.rgb[3 * p + c];
    if (words[p] == 0) {
      interiorChanged += differs;
      continue;
    }
    if (groundId != 0 && ids[p].x == groundId) {
      ++groundEdges;
      groundChanged += differs;
      continue;
    }
    ++edges;
    changed += differs;
  }
  std::printf("antialiasing changed %zu of %zu edge pixels centred on an object, %zu of %zu centred on the ground\n",
              changed, edges, groundChanged, groundEdges);
  EXPECT_EQ(interiorChanged, 0u);
  EXPECT_GT(edges, 100u);
  EXPECT_GT(changed, 9 * edges / 10);
  EXPECT_EQ(a.objectMask, b.objectMask) << "the object mask is the centres' coverage, antialiased or not";
  testing::expectNoValidationMessages(smooth.context());
}

// The exposure chosen on the device (exposure.comp) is the CPU's on the
// same antialiased frame, for a rotating method (batched, split passes);
// the bytes are the frame's own linear image encoded at that exposure.
GPU_TEST(Antialias, DeviceAutoExposureMatchesTheCpuOnARotatingMethod) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  render::RenderOptions o = frameOptions(RotationMethod::Haar, true);
  o.antialias = true;
  const auto cpu = render::makeCpuRenderer(scene, o);
  VulkanRenderer gpu(scene, o, testing::testOptions());
  render::FrameRequest request = turnedRequest(scene, o.width, o.height);
  request.exposure = render::ExposureControl{};  // automatic
  const render::Frame a = cpu->render(request);
  const render::Frame b = gpu.render(request);
  std::printf("auto exposure: cpu %.5f stops, vulkan %.5f stops\n", a.exposureStops, b.exposureStops);
  ASSERT_GT(a.logAverageLuminance, 0.0);
  EXPECT_NEAR(b.exposureStops, a.exposureStops, 0.01);
  EXPECT_NEAR(b.exposureStops, render::meterExposure(b.image, b.objectMask, {}, request.tone).stops, 1e-5);
  const testing::Comparison c = compare(a, b);
  EXPECT_GE(c.psnr, 60.0);
  const auto expected = render::tonemapRgba8(b.image, b.exposureStops);
  ASSERT_EQ(expected.size(), b.rgba8.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) differ += expected[i] != b.rgba8[i];
  // The gain multiplies on the device, the CPU divides the thresholds: a
  // value within a float ulp of a code boundary may land on either side.
  EXPECT_LE(differ, expected.size() / 1000 + 2);
  testing::expectNoValidationMessages(gpu.context());
}

}  // namespace
}  // namespace haarcast::gpu
