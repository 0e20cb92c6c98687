// The functions the CPU and the shaders share (core/shared_frame.h,
// core/shared_tonemap.h, core/shared_exposure.h) read as GLSL
// (shaders/shared_functions_check.comp) against the same lines read as C++
// in float: the camera ray and a sub-sample's coordinate, the shading frame,
// θₒ and the frame's Euler angles, the nearest slice, the display code, the meter's per-pixel weight
// and its read-out. Integer results are compared exactly; float ones to a
// few ulps, which Vulkan lets a device's division, square root and acos
// differ by (and a driver may contract a·b + c into one fma). Where θₒ is
// small the frame's z axis, (wo − (n·wo)n)/|wo − (n·wo)n|, and θₒ itself
// carry those ulps divided by sin θₒ in either language: there the bound
// grows as 1/sin θₒ (on an H100, 3.6·10⁻⁴ where lavapipe matches C++ to the bit).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include "gpu_test_util.h"
#include "haarcast/core/shared_frame.h"
#include "haarcast/core/shared_tonemap.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/render/exposure_meter.h"
#include "haarcast/render/tonemap.h"

namespace haarcast::gpu {
namespace {

using shared::uint;

struct FrameCase {
  glm::vec4 n;       // xyz: normal; w: the tonemapped value
  glm::vec4 wo;      // xyz: toward the eye; w: 1 for an object pixel
  glm::vec4 point;   // px, py, width, height
  glm::uvec4 sub;    // pixel, k, axis bit, 0
  glm::vec4 colour;  // meterWeight's colour
};
static_assert(sizeof(FrameCase) == 80);

struct CheckPush {
  uint count = 0, thetaSamples = 0;
  float tanHalf = 0.0f, aspect = 0.0f;
  shared::ExposurePush exposure{};
};
static_assert(sizeof(CheckPush) == 16 + sizeof(shared::ExposurePush));

bool near(float got, float want, float tolerance) { return std::abs(got - want) <= tolerance * (1.0f + std::abs(want)); }

std::vector<FrameCase> makeCases(const render::ToneThresholds& thresholds) {
  std::mt19937 rng(13);
  std::normal_distribution<float> gauss;
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  auto direction = [&] { return glm::normalize(glm::vec3(gauss(rng), gauss(rng), gauss(rng))); };
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<FrameCase> cases;
  for (uint k = 0; k < 600; ++k) {
    FrameCase c{};
    const glm::vec3 n = direction();
    glm::vec3 wo = direction();
    if (k % 50 == 0) wo = n;                                              // view along the normal: the tangent branch
    if (k % 50 == 1) wo = glm::normalize(glm::vec3(0.95f, 0.3f, 0.1f));  // … with n.x > 0.9
    // Near the normal (θₒ of 1e-4 … 1e-1), where acos is ill-conditioned:
    // the centre of every sphere in view.
    if (k % 5 == 2) wo = glm::normalize(n + std::pow(10.0f, -4.0f + 3.0f * unit(rng)) * direction());
    glm::vec3 normal = k % 50 == 1 ? wo : n;
    if (k % 50 == 3) normal = glm::vec3(0.0f, 1.0f, 0.0f);   // the Euler angles' gimbal pole, β = 0
    if (k % 50 == 4) normal = glm::vec3(0.0f, -1.0f, 0.0f);  // … and β = π
    // The display code: thresholds themselves, values between them, and
    // what must give 0 (NaN, negatives) or 255 (∞).
    float tone = thresholds[1 + k % (shared::kToneCodes - 1)];
    if (k % 3 == 1) tone = std::nextafter(tone, 0.0f);
    if (k % 3 == 2) tone *= 1.0f + unit(rng) * 1e-3f;
    if (k % 97 == 5) tone = nan;
    if (k % 97 == 6) tone = -1.0f;
    if (k % 97 == 7) tone = inf;
    c.n = glm::vec4(normal, tone);
    c.wo = glm::vec4(wo, static_cast<float>(k % 2));
    c.point = glm::vec4(unit(rng) * 640.0f, unit(rng) * 360.0f, 640.0f, 360.0f);
    c.sub = glm::uvec4(k * 7 % 1024, k % shared::kSubsamples, 1u + k % 2, 0u);
    glm::vec3 colour(unit(rng), unit(rng), unit(rng));
    colour *= std::exp2(40.0f * unit(rng) - 20.0f);
    if (k % 11 == 3) colour = glm::vec3(0.0f);
    if (k % 11 == 4) colour.y = inf;
    if (k % 11 == 5) colour.x = nan;
    c.colour = glm::vec4(colour, 0.0f);
    cases.push_back(c);
  }
  return cases;
}

GPU_TEST(SharedFunctions, ShaderAndCppAgreeOnTheFrameTheDisplayCodeAndTheMeter) {
  HAARCAST_REQUIRE_VULKAN();
  const render::ToneThresholds thresholds = render::tonemapThresholds(0.7, render::ToneCurve::Reinhard);
  const std::vector<FrameCase> cases = makeCases(thresholds);
  const glm::vec4 basis[3] = {glm::vec4(glm::normalize(glm::vec3(0.2f, -0.3f, -1.0f)), 0.0f),
                              glm::vec4(glm::normalize(glm::vec3(1.0f, 0.0f, 0.2f)), 0.0f),
                              glm::vec4(glm::normalize(glm::vec3(-0.06f, 0.95f, -0.3f)), 0.0f)};
  render::ExposureHistograms histograms;
  std::mt19937 rng(14);
  std::uniform_int_distribution<uint> bin(200, 700), count(1, 40);
  for (int i = 0; i < 300; ++i) {
    histograms.luminance[bin(rng)] += count(rng);
    histograms.peak[bin(rng) + 20] += count(rng);
  }
  render::ExposureControl control;
  control.previousStops = 1.5;
  control.adaptation = 0.3;

  CheckPush push;
  push.count = static_cast<uint>(cases.size());
  push.thetaSamples = 16;
  push.tanHalf = 0.41f;
  push.aspect = 640.0f / 360.0f;
  push.exposure = render::exposurePush(control, render::ToneCurve::Aces);

  Context context(testing::testOptions());
  Buffer caseBuf(context, cases.size() * sizeof(FrameCase)), basisBuf(context, sizeof basis),
      thresholdBuf(context, sizeof thresholds), histogramBuf(context, sizeof histograms),
      resultBuf(context, 5 * cases.size() * sizeof(glm::vec4)), readoutBuf(context, sizeof(shared::ExposureResult));
  caseBuf.upload(std::span<const FrameCase>(cases));
  basisBuf.write(basis, sizeof basis);
  thresholdBuf.write(thresholds.data(), sizeof thresholds);
  histogramBuf.write(&histograms, sizeof histograms);
  ComputePipeline check(context, "shared_functions_check.comp", 6, sizeof(CheckPush));
  check.bind({&caseBuf, &basisBuf, &thresholdBuf, &histogramBuf, &resultBuf, &readoutBuf});
  context.submit([&](VkCommandBuffer cb) {
    check.dispatch(cb, {(push.count + shared::kLocalSize - 1) / shared::kLocalSize, 1, 1}, &push, sizeof push);
    computeBarrier(cb);
  });
  std::vector<glm::vec4> got(5 * cases.size());
  resultBuf.download(std::span<glm::vec4>(got));
  shared::ExposureResult readout{};
  readoutBuf.read(&readout, sizeof readout);

  constexpr float kTolerance = 4e-6f;
  // The ill-conditioned part: 16 float ulps of 1 (2⁻²⁴ each) of error in
  // wo − (n·wo)n, over its length sin θₒ.
  constexpr double kConditionedUlps = 16.0 * 0x1p-24;
  std::size_t wrong = 0;
  std::map<std::string, std::size_t> wrongByKind;
  double worstFrameShare = 0.0;  // the largest |GLSL − C++| of a frame axis, as a share of its bound
  auto expect = [&](bool ok, std::size_t k, const char* what, float glsl, float cpp) {
    if (ok) return;
    ++wrong;
    if (++wrongByKind[what] > 3) return;
    ADD_FAILURE() << "case " << k << " " << what << ": GLSL " << glsl << ", C++ " << cpp;
  };
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const FrameCase& c = cases[k];
    // sin θₒ of the case, in double; the tangent branch (|z| < 10⁻⁸) is exact.
    const glm::dvec3 dn(c.n), dwo(c.wo);
    const double sinTheta = glm::length(dwo - glm::dot(dn, dwo) * dn);
    const float conditioned = sinTheta > 1e-8 ? static_cast<float>(kConditionedUlps / sinTheta) : 0.0f;
    const float frameTolerance = kTolerance + conditioned;
    const glm::vec3 ray = shared::cameraDirectionAt<float>(glm::vec3(basis[0]), glm::vec3(basis[1]), glm::vec3(basis[2]),
                                                           push.tanHalf, push.aspect, c.point.z, c.point.w, c.point.x,
                                                           c.point.y);
    for (int e = 0; e < 3; ++e) expect(near(got[5 * k][e], ray[e], kTolerance), k, "camera ray", got[5 * k][e], ray[e]);
    const float coordinate = shared::subsampleCoordinate<float>(c.sub.x, c.sub.y, c.sub.z);
    expect(got[5 * k].w == coordinate, k, "sub-sample coordinate", got[5 * k].w, coordinate);

    float thetaOut = 0.0f;
    const glm::mat3 frame = shared::shadingFrame<float>(glm::vec3(c.n), glm::vec3(c.wo), thetaOut);
    for (int e = 0; e < 3; ++e) {
      expect(near(got[5 * k + 1][e], frame[0][e], frameTolerance), k, "frame x", got[5 * k + 1][e], frame[0][e]);
      expect(near(got[5 * k + 2][e], frame[2][e], frameTolerance), k, "frame z", got[5 * k + 2][e], frame[2][e]);
      for (const auto& [glsl, cpp] : {std::pair(got[5 * k + 1][e], frame[0][e]), std::pair(got[5 * k + 2][e], frame[2][e])}) {
        const double bound = frameTolerance * (1.0 + std::abs(cpp));
        worstFrameShare = std::max(worstFrameShare, std::abs(static_cast<double>(glsl) - cpp) / bound);
      }
    }
    const float deviceTheta = got[5 * k + 1].w;
    expect(near(deviceTheta, thetaOut, frameTolerance), k, "θₒ", deviceTheta, thetaOut);
    // The slice from the device's own θₒ: the same float in, the same cell out.
    const uint slice = shared::sliceBlendAt(deviceTheta, push.thetaSamples, 0u).first;
    const uint deviceSlice = std::bit_cast<uint>(got[5 * k + 2].w);
    expect(deviceSlice == slice, k, "nearest slice", static_cast<float>(deviceSlice), static_cast<float>(slice));

    const uint code = shared::tonemapCode(c.n.w, thresholds);
    const uint deviceCode = std::bit_cast<uint>(got[5 * k + 3].x);
    expect(deviceCode == code, k, "display code", static_cast<float>(deviceCode), static_cast<float>(code));
    // The Euler angles: β directly; α and γ through the rotation they make
    // (at the poles only their sum or difference is fixed), each side's
    // angles of its own frame. (Not against the frame itself: with θₒ near 0
    // its z axis, wo − (n·wo)n normalised, is n's orthogonal only to float
    // rounding over |wo − (n·wo)n|, in both languages alike.)
    const glm::vec3 euler(got[5 * k + 4]);
    const glm::vec3 want = shared::eulerYXYOf(frame);
    expect(near(euler.y, want.y, kTolerance), k, "Euler β", euler.y, want.y);
    const auto rotation = [](const glm::vec3& e) {
      return shared::rotY(static_cast<double>(e.x)) * shared::rotX(static_cast<double>(e.y)) *
             shared::rotY(static_cast<double>(e.z));
    };
    const glm::dmat3 fromDevice = rotation(euler), fromCpp = rotation(want);
    for (int col = 0; col < 3; ++col) {
      for (int row = 0; row < 3; ++row) {
        expect(std::abs(fromDevice[col][row] - fromCpp[col][row]) <= 2e-5 + 2.0 * conditioned, k, "R_y(α)R_x(β)R_y(γ)",
               static_cast<float>(fromDevice[col][row]), static_cast<float>(fromCpp[col][row]));
      }
    }
    const uint weight = shared::meterWeight(shared::meterLuminance(glm::vec3(c.colour)), c.wo.w != 0.0f);
    const uint deviceWeight = std::bit_cast<uint>(got[5 * k + 3].y);
    expect(deviceWeight == weight, k, "meter weight", static_cast<float>(deviceWeight), static_cast<float>(weight));
  }
  std::string kinds;
  for (const auto& [what, n] : wrongByKind) kinds += " " + what + ": " + std::to_string(n) + ";";
  EXPECT_EQ(wrong, 0u) << "of " << cases.size() << " cases, by kind:" << kinds;
  std::printf("shared frame: the frame axes' worst |GLSL − C++| is %.3f of its bound\n", worstFrameShare);

  const shared::ExposureResult want = shared::meterReadout(histograms, push.exposure);
  ASSERT_GT(want.weight, 0u);
  EXPECT_EQ(readout.weight, want.weight);
  EXPECT_PRED3(near, readout.meanLog2, want.meanLog2, kTolerance);
  EXPECT_EQ(readout.highlightLog2, want.highlightLog2);
  EXPECT_PRED3(near, readout.stops, want.stops, kTolerance);
  EXPECT_PRED3(near, readout.logAverage, want.logAverage, kTolerance);
  EXPECT_PRED3(near, readout.gain, want.gain, kTolerance);
  testing::expectNoValidationMessages(context);
}

}  // namespace
}  // namespace haarcast::gpu
