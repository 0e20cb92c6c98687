// Shadow rays on the device (gpu/ray_tracing.h, device_rays.cpp,
// shaders/shadow_rays.rgen) against the host's (Embree, the CPU backend's
// rays) for the very same samples: two renderers of one scene, one with
// --rays host and one with --rays device, render one request; their
// G-buffers and samples are the same, so every sample's shadow word can be
// compared bit by bit.
//
// Why not equal: Embree and a driver's traversal differ in watertightness
// (a ray through a shared edge or vertex may hit on one and slip through on
// the other) and the shading point is the same expression in C++ and GLSL
// but not always the same float (fused multiply-adds). A ray that grazes a
// surface or passes an edge can so flip; a few per thousand. The ground's
// occlusion is a sum of such rays: its share moves by a ray's weight where
// one flips.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "frame_compare.h"
#include "gpu_test_util.h"
#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/core/brdf.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/shared_smooth.h"
#include "haarcast/gpu/vulkan_renderer.h"
#include "haarcast/render/renderer.h"

namespace haarcast::gpu {
namespace {

using testing::compare;
using testing::Comparison;
using testing::frameOptions;
using testing::requestFor;

// Skips where the device cannot trace rays (Debian 12's own Mesa), unless
// the environment says it must (deploy/run.sh test installs a lavapipe
// that does and sets HAARCAST_REQUIRE_RAY_TRACING=1: there a skip would hide
// a broken install, so it fails instead).
bool rayTracingOrSkip() {
  Context context(testing::testOptions());
  if (context.rayTracing().supported) return true;
  const char* required = std::getenv("HAARCAST_REQUIRE_RAY_TRACING");
  if (required && std::string(required) == "1") {
    ADD_FAILURE() << context.info().name << " cannot trace rays (" << context.rayTracing().missing
                  << ") and HAARCAST_REQUIRE_RAY_TRACING=1";
  }
  return false;
}

#define HAARCAST_REQUIRE_RAY_TRACING()                                          \
  do {                                                                          \
    HAARCAST_REQUIRE_VULKAN();                                                  \
    if (!rayTracingOrSkip()) GTEST_SKIP() << "the Vulkan device cannot trace rays"; \
  } while (0)

VulkanRendererLimits raysOn(render::RayMode mode) {
  VulkanRendererLimits l;
  l.rays = mode;
  return l;
}

// What differs between two renderers' shadow words, sample by sample
// (matched by their radiance slot).
struct WordDiff {
  std::size_t samples = 0;
  std::size_t lightRays = 0, lightFlipped = 0;  // (sample, light) pairs above the horizon on either
  std::size_t lobeSamples = 0, lobeFlipped = 0;
  std::size_t groundSamples = 0, groundOff = 0;  // off: the occlusion differs by more than kGroundSlack
  double groundWorst = 0.0;
  std::size_t groundOccluded = 0;  // ground samples with some occlusion on the host
  // The sky the other objects hide (HiddenLight), on the objects' samples:
  // those with some on the host, those whose Σ power·(n·d)… differs by more
  // than kHiddenSlack of the largest, and whose directions differ by more
  // than 0.05 rad where both hide something.
  std::size_t hiddenSamples = 0, hiddenOff = 0, hiddenTurned = 0;
  double hiddenLargest = 0.0;
};
// A ray's share of a cone, as kGroundSlack.
constexpr double kHiddenSlack = 0.05;
// A ray's weight in one 2 × 8 cone is at most a few per cent of the sky;
// flips of one or two rays stay under this.
constexpr double kGroundSlack = 0.05;

// groundSky: the ground's word carries its hidden sky (`fused`); else
// (`splitsum`) its upper bit is the lobe's, as on every object.
WordDiff diffWords(const VulkanRenderer& host, const VulkanRenderer& device, bool groundSky) {
  WordDiff d;
  const std::vector<ShadeSample> hs = host.shadeSamples(), ds = device.shadeSamples();
  const std::vector<std::uint32_t> hw = host.shadowWords(), dw = device.shadowWords();
  const std::vector<HiddenLight> hh = host.hiddenLights(), dh = device.hiddenLights();
  EXPECT_EQ(hh.size(), groundSky ? hw.size() : 0u) << "fused with two objects on a ground hides sky";
  EXPECT_EQ(dh.size(), hh.size());
  for (const HiddenLight& l : hh) d.hiddenLargest = std::max(d.hiddenLargest, static_cast<double>(l.power.x));
  EXPECT_EQ(hs.size(), hw.size());
  EXPECT_EQ(ds.size(), dw.size());
  EXPECT_EQ(hs.size(), ds.size());  // the same G-buffer: the same covered samples
  std::map<std::uint32_t, std::size_t> hostAt;
  for (std::size_t s = 0; s < hs.size(); ++s) hostAt[hs[s].pixel] = s;
  const render::PreparedScene& prepared = host.prepared();
  const std::uint32_t lightMask = (1u << shared::kMaxPointLights) - 1u;
  for (std::size_t s = 0; s < ds.size(); ++s) {
    const auto it = hostAt.find(ds[s].pixel);
    if (it == hostAt.end()) {
      ADD_FAILURE() << "device sample of slot " << ds[s].pixel << " has no host sample";
      continue;
    }
    const ShadeSample& h = hs[it->second];
    EXPECT_EQ(h.object, ds[s].object);
    if (h.object >= prepared.objects.size()) continue;
    ++d.samples;
    const std::uint32_t a = hw[it->second], b = dw[s];
    const std::uint32_t lights = (a | b) & lightMask;
    d.lightRays += static_cast<std::size_t>(__builtin_popcount(lights));
    d.lightFlipped += static_cast<std::size_t>(__builtin_popcount((a ^ b) & lightMask));
    const render::PreparedObject& o = prepared.objects[h.object];
    if (o.ground && groundSky) {
      ++d.groundSamples;
      const double ha = static_cast<double>(a >> shared::kGroundOcclusionShift) / shared::kGroundOcclusionSteps;
      const double db = static_cast<double>(b >> shared::kGroundOcclusionShift) / shared::kGroundOcclusionSteps;
      if (ha > 0.0) ++d.groundOccluded;
      d.groundWorst = std::max(d.groundWorst, std::abs(ha - db));
      if (std::abs(ha - db) > kGroundSlack) ++d.groundOff;
    } else {
      if (o.lobePath || !groundSky) {
        ++d.lobeSamples;
        if ((a ^ b) & shared::kLobeSeenBit) ++d.lobeFlipped;
      }
      EXPECT_EQ(a >> (shared::kMaxPointLights + 1), 0u);  // nothing above the lobe's bit off the ground
      EXPECT_EQ(b >> (shared::kMaxPointLights + 1), 0u);
      if (!hh.empty()) {
        const HiddenLight& x = hh[it->second];
        const HiddenLight& y = dh[s];
        if (x.power.x > 0.0f) ++d.hiddenSamples;
        if (std::abs(x.power.x - y.power.x) > kHiddenSlack * d.hiddenLargest) ++d.hiddenOff;
        const glm::vec3 u = shared::unpackDirection(x.direction), v = shared::unpackDirection(y.direction);
        if (x.power.x > 0.0f && y.power.x > 0.0f && glm::dot(u, v) < std::cos(0.05f)) ++d.hiddenTurned;
      }
    }
  }
  return d;
}

// A request of the scene at o's size with its second object turned: shadows
// between the objects that the scene's own poses do not line up.
render::FrameRequest turnedRequest(const render::Scene& scene, const render::RenderOptions& o) {
  render::FrameRequest request = requestFor(scene, o.width, o.height);
  request.poses = testing::scenePoses(scene);
  request.poses[1].rotateDegrees += glm::dvec3(10.0, 25.0, -5.0);
  return request;
}

struct RaysCase {
  const char* name;
  RotationMethod method;
  bool mirror;     // the first object a near-mirror (the lobe path), the second a hazy one
  bool antialias;
  // Ten objects: seven small spheres more, the last (object 9, whose
  // instance mask bit is the torus's, object 1: shared_rays.h rayMaskOf)
  // just above the torus, so that it hides sky from it.
  bool crowded = false;
};

void PrintTo(const RaysCase& c, std::ostream* os) { *os << c.name; }

class DeviceRays : public testing::GpuTestWithParam<RaysCase> {};

// The default scene (two objects on a ground, point lights from its probe),
// the second object and the light turned: shadows between the objects, on
// the ground, the ground's hidden sky; with mirrors, the lobe rays.
TEST_P(DeviceRays, ShadowWordsMatchTheHostsRays) {
  HAARCAST_REQUIRE_RAY_TRACING();
  const RaysCase& c = GetParam();
  render::Scene scene = render::defaultScene();
  ASSERT_GE(scene.objects.size(), 3u);
  if (c.mirror) {
    scene.objects[0].material = {"ggx:0.002", "test-mirror", makeGgx(glm::dvec3(0.0), glm::dvec3(0.9), 0.002), ""};
    scene.objects[1].material = {"hazy mirror", "test-hazy", makeGgx(glm::dvec3(0.3), glm::dvec3(0.9), 0.005), ""};
  }
  if (c.crowded) {
    const auto ball = std::make_shared<Mesh>(assets::makeSphere(16));
    for (int k = 0; k < 6; ++k) {
      render::SceneObject s{"ball " + std::to_string(k), ball, render::materialFromSpec("lambert"), {}};
      s.pose.scale = 0.08;
      s.pose.translate = {-1.9 + 0.3 * k, -0.5, -1.2};
      scene.objects.push_back(std::move(s));
    }
    render::SceneObject above{"above the torus", ball, render::materialFromSpec("lambert"), {}};
    above.pose.scale = 0.3;
    above.pose.translate = {0.8, 0.75, 0.1};
    scene.objects.push_back(std::move(above));
    ASSERT_EQ(scene.objects.size(), 10u);
    ASSERT_EQ(shared::rayMaskOf(9u), shared::rayMaskOf(1u));
  }
  render::RenderOptions o = frameOptions(c.method, true);
  o.width = 96;
  o.height = 72;
  o.antialias = c.antialias;
  VulkanRenderer host(scene, o, testing::testOptions(), {}, raysOn(render::RayMode::Host));
  VulkanRenderer device(scene, o, testing::testOptions(), {}, raysOn(render::RayMode::Device));
  EXPECT_EQ(host.rays(), "host");
  EXPECT_EQ(device.rays(), "device");
  render::FrameRequest request = turnedRequest(scene, o);
  request.lightRotation = rotationMatrix({0.3, -0.4, 0.1});
  const render::Frame a = host.render(request);
  const render::Frame b = device.render(request);
  const WordDiff d = diffWords(host, device, c.method == RotationMethod::Fused);
  const Comparison image = compare(a, b);
  std::printf("%s: %zu samples; light rays %zu, %zu flipped; lobe samples %zu, %zu flipped; ground samples %zu "
              "(%zu occluded), %zu off by > %.2f, worst %.4f; hidden sky on %zu samples, %zu off, %zu turned; "
              "image %.1f dB\n",
              c.name, d.samples, d.lightRays, d.lightFlipped, d.lobeSamples, d.lobeFlipped, d.groundSamples,
              d.groundOccluded, d.groundOff, kGroundSlack, d.groundWorst, d.hiddenSamples, d.hiddenOff, d.hiddenTurned,
              image.psnr);
  EXPECT_GT(d.samples, 3000u);
  // The rays this scene must exercise: its lights, its ground's hidden sky,
  // and with mirrors the lobe path.
  if (c.method == RotationMethod::Fused) {
    EXPECT_GT(d.lightRays, d.samples);
    EXPECT_GT(d.groundOccluded, 100u);
    EXPECT_GT(d.hiddenSamples, 100u) << "the objects hide sky from each other";
  }
  if (c.mirror || c.method == RotationMethod::Splitsum) {
    EXPECT_GT(d.lobeSamples, 500u);
  }
  // At most 2 in 1,000 of the rays flip (watertightness, above).
  EXPECT_LE(d.lightFlipped * 500, d.lightRays);
  EXPECT_LE(d.lobeFlipped * 500, std::max<std::size_t>(d.lobeSamples, 1));
  EXPECT_LE(d.groundOff * 500, std::max<std::size_t>(d.groundSamples, 1));
  EXPECT_LE((d.hiddenOff + d.hiddenTurned) * 500, std::max<std::size_t>(d.hiddenSamples, 1));
  // The image: the same but where a ray flipped.
  EXPECT_GE(image.psnr, 60.0);
  EXPECT_EQ(image.mismatched, 0u);
  testing::expectNoValidationMessages(device.context());
}

INSTANTIATE_TEST_SUITE_P(Cases, DeviceRays,
                         ::testing::Values(RaysCase{"fused", RotationMethod::Fused, false, false},
                                           RaysCase{"fused-antialiased", RotationMethod::Fused, false, true},
                                           RaysCase{"fused-mirrors", RotationMethod::Fused, true, false},
                                           RaysCase{"splitsum", RotationMethod::Splitsum, false, false},
                                           RaysCase{"fused-ten-objects", RotationMethod::Fused, false, false, true}),
                         [](const ::testing::TestParamInfo<RaysCase>& param) {
                           std::string name = param.param.name;
                           for (char& ch : name) ch = ch == '-' ? '_' : ch;
                           return name;
                         });

// The ground's hidden sky as sky jobs (each job's rays over kSkyLanes
// invocations, shared_rays.h) against a list of one job, where every other
// job traces its rays in the invocation it arose in: the same rays, added
// in another order, so the same words but for a share that rounds to the
// next step. Antialiased, so that sub-samples take jobs of their own too.
GPU_TEST(DeviceRays, ASkyJobsLanesTraceWhatOneInvocationDoes) {
  HAARCAST_REQUIRE_RAY_TRACING();
  const render::Scene scene = render::defaultScene();
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  o.width = 96;
  o.height = 72;
  o.antialias = true;
  VulkanRendererLimits oneJob = raysOn(render::RayMode::Device);
  oneJob.skyJobs = 1;
  VulkanRenderer inOne(scene, o, testing::testOptions(), {}, oneJob);
  VulkanRenderer lanes(scene, o, testing::testOptions(), {}, raysOn(render::RayMode::Device));
  render::FrameRequest request = turnedRequest(scene, o);
  const render::Frame a = inOne.render(request);
  const render::Frame b = lanes.render(request);
  const WordDiff d = diffWords(inOne, lanes, true);
  const Comparison image = compare(a, b);
  std::printf("%zu ground samples (%zu occluded), worst %.5f apart; image %.1f dB\n", d.groundSamples, d.groundOccluded,
              d.groundWorst, image.psnr);
  EXPECT_GT(d.groundOccluded, 1000u);
  EXPECT_EQ(d.lightFlipped, 0u);
  EXPECT_EQ(d.lobeFlipped, 0u);
  EXPECT_EQ(d.hiddenOff + d.hiddenTurned, 0u);
  EXPECT_LE(d.groundWorst, 1.0 / shared::kGroundOcclusionSteps + 1e-9);
  EXPECT_GE(image.psnr, 90.0);
  EXPECT_EQ(image.mismatched, 0u);
  testing::expectNoValidationMessages(lanes.context());
}

// With sums from neighbours the device traces the sky other objects hide
// from a sample of the smooth sum's stages 1 and on only where that stage
// sums it itself (shared_rays.h kRaysPhaseHidden); the host traces every
// sample's. The frames agree as with every other ray; the device's hidden
// lights are the host's where traced, and none where the sum came from the
// parents, which reads none.
GPU_TEST(DeviceRays, ASmoothStageTracesTheHiddenSkyOfWhatItSumsItself) {
  HAARCAST_REQUIRE_RAY_TRACING();
  const render::Scene scene = render::defaultScene();
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  o.width = 96;
  o.height = 72;
  o.smoothSumTolerance = shared::kDefaultSmoothSumTolerance;
  VulkanRenderer host(scene, o, testing::testOptions(), {}, raysOn(render::RayMode::Host));
  VulkanRenderer device(scene, o, testing::testOptions(), {}, raysOn(render::RayMode::Device));
  render::FrameRequest request = turnedRequest(scene, o);
  const render::Frame a = host.render(request);
  const render::Frame b = device.render(request);
  const Comparison image = compare(a, b);
  const std::vector<ShadeSample> hs = host.shadeSamples(), ds = device.shadeSamples();
  const std::vector<HiddenLight> hh = host.hiddenLights(), dh = device.hiddenLights();
  ASSERT_EQ(hs.size(), hh.size());
  ASSERT_EQ(ds.size(), dh.size());
  std::map<std::uint32_t, std::size_t> hostAt;
  for (std::size_t s = 0; s < hs.size(); ++s) hostAt[hs[s].pixel] = s;
  double largest = 0.0;
  for (const HiddenLight& l : hh) largest = std::max(largest, static_cast<double>(l.power.x));
  std::size_t onHost = 0, traced = 0, left = 0, off = 0;
  for (std::size_t s = 0; s < ds.size(); ++s) {
    const HiddenLight& x = hh[hostAt.at(ds[s].pixel)];
    const HiddenLight& y = dh[s];
    if (!(x.power.x > 0.0f)) continue;
    ++onHost;
    if (y.power.x > 0.0f) {
      ++traced;
      if (std::abs(x.power.x - y.power.x) > kHiddenSlack * largest) ++off;
    } else {
      ++left;
    }
  }
  std::printf("hidden sky on %zu samples on the host; the device traced %zu (%zu off), left %zu to their parents' sums; "
              "image %.1f dB\n", onHost, traced, off, left, image.psnr);
  EXPECT_GT(onHost, 100u);
  EXPECT_GE(traced * 2, onHost) << "the stages' own sums trace theirs";
  EXPECT_GT(left, 0u) << "a sum taken from the parents traces none";
  EXPECT_LE(off * 500, onHost);
  EXPECT_GE(image.psnr, 60.0);
  EXPECT_EQ(image.mismatched, 0u);
  testing::expectNoValidationMessages(device.context());
}

// With the rays on the device a frame is one submission; with the host's,
// three (the first part, the covered samples' copy read back, and after the
// host's rays the second part with the words' upload). Counted
// on the renderer's Context, one frame after a warm-up frame of the same size.
GPU_TEST(DeviceRays, AFrameIsOneSubmission) {
  HAARCAST_REQUIRE_RAY_TRACING();
  const render::Scene scene = render::defaultScene();
  render::RenderOptions o = frameOptions(RotationMethod::Fused, true);
  for (const render::RayMode mode : {render::RayMode::Device, render::RayMode::Host}) {
    VulkanRendererLimits limits = raysOn(mode);
    limits.oneSubmission = true;  // a CPU device's stages in one submission too
    VulkanRenderer renderer(scene, o, testing::testOptions(), {}, limits);
    const render::FrameRequest request = requestFor(scene, o.width, o.height);
    renderer.render(request);
    const std::uint64_t before = renderer.context().submissionCount();
    const render::Frame frame = renderer.render(request);
    const std::uint64_t submissions = renderer.context().submissionCount() - before;
    std::printf("rays %s: %llu submission(s) a frame\n", renderer.rays().c_str(),
                static_cast<unsigned long long>(submissions));
    EXPECT_EQ(submissions, mode == render::RayMode::Device ? 1u : 3u);
    EXPECT_FALSE(frame.rgba8.empty());
  }
}

// The rotating methods trace no rays, whatever --rays says.
GPU_TEST(DeviceRays, TheRotatingMethodsTraceNone) {
  HAARCAST_REQUIRE_VULKAN();
  const render::Scene scene = render::defaultScene();
  render::RenderOptions o = frameOptions(RotationMethod::Haar, true);
  VulkanRenderer renderer(scene, o, testing::testOptions(), {}, raysOn(render::RayMode::Host));
  EXPECT_EQ(renderer.rays(), "none");
}

}  // namespace
}  // namespace haarcast::gpu
