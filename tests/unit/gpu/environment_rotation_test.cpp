// The scene's own environment turn (render::Environment::rotation, a scene
// file's "environment": {"rotate": …}) on the Vulkan backend: a turned
// scene renders as the CPU backend renders it, and as the unturned scene
// under the same light pose (render::lightRotationOf, one definition for both).
#include <gtest/gtest.h>

#include <cstdio>

#include "frame_compare.h"
#include "gpu_test_util.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/gpu/vulkan_renderer.h"
#include "haarcast/render/renderer.h"

namespace haarcast::gpu {
namespace {

using testing::compare;
using testing::Comparison;
using testing::frameOptions;
using testing::requestFor;

GPU_TEST(EnvironmentRotation, ATurnedSceneRendersAsTheCpuAndAsTheLightPose) {
  HAARCAST_REQUIRE_VULKAN();
  render::Pose pose;
  pose.rotateDegrees = {15.0, -70.0, 5.0};
  const glm::dmat3 turn = pose.rotation();
  const render::Scene plain = render::defaultScene();
  render::Scene turned = plain;
  render::rotateEnvironment(turned.environment, turn);
  const render::RenderOptions o = frameOptions(RotationMethod::Fused, true);

  const auto cpu = render::makeCpuRenderer(turned, o);
  VulkanRenderer gpuTurned(turned, o, testing::testOptions());
  VulkanRenderer gpuPlain(plain, o, testing::testOptions());
  const render::FrameRequest request = requestFor(turned, o.width, o.height);
  render::FrameRequest posed = request;
  posed.lightRotation = turn;
  const render::Frame reference = cpu->render(request);
  const render::Frame a = gpuTurned.render(request);
  const render::Frame b = gpuPlain.render(posed);
  const render::Frame unturned = gpuPlain.render(request);
  const Comparison vsCpu = compare(reference, a), vsPose = compare(b, a), vsUnturned = compare(unturned, a);
  std::printf("turned environment: Vulkan vs CPU %.1f dB, vs the light pose %.1f dB, vs unturned %.1f dB\n", vsCpu.psnr,
              vsPose.psnr, vsUnturned.psnr);
  EXPECT_GE(vsCpu.psnr, testing::fusedPsnrFloor(gpuTurned.context()));
  EXPECT_GE(vsPose.psnr, testing::fusedPsnrFloor(gpuTurned.context()));
  EXPECT_LT(vsUnturned.psnr, 40.0);  // the turn shows
  testing::expectNoValidationMessages(gpuTurned.context());
}

}  // namespace
}  // namespace haarcast::gpu
