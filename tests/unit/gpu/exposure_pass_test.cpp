// exposure.comp and exposure_readout.comp driven alone against
// render::meterExposure on the same linear frame: auto exposure's metering
// (core/shared_exposure.h) counts the same integer histograms on the device
// as on the CPU, so the highlight bin and the weight agree exactly and the
// exposure to float rounding, for every tone curve, with and without easing,
// for a fixed exposure, and however many workgroups share the frame.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <span>
#include <vector>

#include "gpu_test_util.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/gpu/passes.h"
#include "haarcast/render/exposure_meter.h"

namespace haarcast::gpu {
namespace {

struct MeterCase {
  const char* name;
  render::ExposureControl control;
};

// A frame like the sky-clipping one: dim objects in the middle, a backdrop
// spanning 12 stops up to a few sun-bright pixels, and pixels that carry no
// light (black, negative, NaN, ∞).
struct TestFrame {
  int width = 61, height = 47;  // not a multiple of the workgroup
  std::vector<glm::uvec4> ids;
  std::vector<glm::vec4> radiance;
  io::RgbImage image;
  std::vector<std::uint8_t> mask;
};

TestFrame testFrame() {
  TestFrame f;
  const std::size_t pixels = static_cast<std::size_t>(f.width) * static_cast<std::size_t>(f.height);
  f.ids.assign(pixels, glm::uvec4(0));
  f.radiance.assign(pixels, glm::vec4(0.0f));
  f.image = io::makeImage(f.width, f.height);
  f.mask.assign(pixels, 0);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(f.width) + static_cast<std::size_t>(x);
      const bool object = std::abs(x - f.width / 2) < 15 && std::abs(y - f.height / 2) < 12;
      glm::vec3 c;
      if (object) {
        c = glm::vec3(0.05f, 0.04f, 0.03f) * std::exp2(4.0f * u(rng) - 2.0f);
      } else {
        c = glm::vec3(0.6f, 0.8f, 1.2f) * std::exp2(12.0f * u(rng) - 4.0f);
      }
      if (p % 97 == 0) c = glm::vec3(0.0f);
      if (p % 101 == 0) c = glm::vec3(-1.0f, 0.0f, 0.0f);
      if (p % 103 == 0) c.y = NAN;
      if (p % 107 == 0) c.z = INFINITY;
      if (p % 211 == 0) c = glm::vec3(5e4f);  // the sun
      f.ids[p].x = object ? 1u : 0u;
      f.mask[p] = object ? 1 : 0;
      f.radiance[p] = glm::vec4(c, 0.0f);
      for (int k = 0; k < 3; ++k) f.image.at(y, x, k) = c[k];
    }
  }
  return f;
}

GPU_TEST(ExposurePass, MetersAsTheCpuForEveryCurveAndControl) {
  HAARCAST_REQUIRE_VULKAN();
  const TestFrame f = testFrame();
  const std::size_t pixels = f.ids.size();
  Context context(testing::testOptions());
  FrameParams params{};
  params.width = static_cast<std::uint32_t>(f.width);
  params.height = static_cast<std::uint32_t>(f.height);
  Buffer paramBuf(context, sizeof params), idBuf(context, pixels * 16), radBuf(context, pixels * 16),
      resultBuf(context, sizeof(ExposureResult)), histogramBuf(context, 2 * shared::kMeterBins * sizeof(std::uint32_t));
  paramBuf.write(&params, sizeof params);
  idBuf.upload(std::span<const glm::uvec4>(f.ids));
  radBuf.upload(std::span<const glm::vec4>(f.radiance));
  ComputePipeline exposure(context, "exposure.comp", shared::kExposureBindings, 0);
  ComputePipeline readout(context, "exposure_readout.comp", shared::kExposureBindings, sizeof(ExposurePush));
  exposure.bind({&paramBuf, &idBuf, &radBuf, &resultBuf, &histogramBuf});
  readout.bind({&paramBuf, &idBuf, &radBuf, &resultBuf, &histogramBuf});
  // The renderer's split (gpu frame_stages.cpp) and others: one workgroup,
  // and more workgroups than the frame has pixels per invocation.
  const std::uint32_t natural = static_cast<std::uint32_t>(
      (pixels + shared::kExposureLocalSize * shared::kExposurePixelsPerInvocation - 1) /
      (shared::kExposureLocalSize * shared::kExposurePixelsPerInvocation));
  ASSERT_GE(natural, 2u);  // the frame is split by the renderer's rule

  render::ExposureControl eased;
  eased.previousStops = 1.5;
  eased.adaptation = 0.3;
  render::ExposureControl fixed;
  fixed.automatic = false;
  fixed.stops = -2.25;
  const std::vector<MeterCase> cases = {{"auto", {}}, {"eased", eased}, {"fixed", fixed}};
  for (const render::ToneCurve tone : render::kToneCurves) {
    for (const MeterCase& c : cases) {
      for (const std::uint32_t groups : {1u, natural, 7u, 29u}) {
        const ExposurePush push = render::exposurePush(c.control, tone);
        context.submit([&](VkCommandBuffer cb) {
          vkCmdFillBuffer(cb, histogramBuf.handle(), 0, VK_WHOLE_SIZE, 0u);
          computeBarrier(cb);
          exposure.dispatch(cb, {groups, 1, 1});
          computeBarrier(cb);
          readout.dispatch(cb, {1, 1, 1}, &push, sizeof push);
        });
        ExposureResult got{};
        resultBuf.read(&got, sizeof got);
        const ExposureResult want = render::meterExposure(f.image, f.mask, c.control, tone);
        const std::string what =
            std::string(render::toneCurveName(tone)) + ", " + c.name + ", " + std::to_string(groups) + " workgroups";
        ASSERT_GT(want.weight, 0u);
        EXPECT_EQ(got.weight, want.weight) << what;
        EXPECT_EQ(got.highlightLog2, want.highlightLog2) << what;
        // One pixel in a neighbouring bin would move the mean by 1/16 · its
        // weight / the total weight, ≥ 1e-5 here.
        EXPECT_NEAR(got.meanLog2, want.meanLog2, 1e-6) << what;
        EXPECT_NEAR(got.logAverage, want.logAverage, 1e-5 * want.logAverage) << what;
        EXPECT_NEAR(got.stops, want.stops, 1e-5) << what;
        EXPECT_NEAR(got.gain, want.gain, 1e-5 * want.gain) << what;
      }
    }
  }
  // The frame is one where the guard acts: the key alone would clip the sky.
  const ExposureResult automatic = render::meterExposure(f.image, f.mask, {}, render::ToneCurve::Reinhard);
  const double key = std::log2(render::kExposureKey) - automatic.meanLog2;
  EXPECT_LT(automatic.stops, key - 0.5);
  testing::expectNoValidationMessages(context);
}

}  // namespace
}  // namespace haarcast::gpu
