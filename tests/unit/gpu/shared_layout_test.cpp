// The Haar numbers of core/shared_layout.h read as GLSL (shaders/
// shared_layout_check.comp) against the same lines read as C++: the preorder
// key and its decoding, the child quadrant and signs, the detail index and
// its inverse, for every block and band of levels 1–7 and sampled blocks up
// to the largest level whose keys fit 32 bits, bit for bit; and the point
// lights' lookup (Catmull-Rom weights, the point value from a texel's mean),
// to float rounding (a device may fuse a multiply and an add); and the
// passes' interface (core/shared_passes.h): π, the workgroup sizes, the level
// caps and every binding number and count as the shader sees them, and the
// push blocks' members where C++ puts them.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <random>
#include <span>
#include <vector>

#include <glm/vec4.hpp>

#include "gpu_test_util.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/shared_tonemap.h"
#include "haarcast/gpu/compute.h"

namespace haarcast::gpu {
namespace {

using shared::uint;

// The check shader's push block: its case count, then the passes' push
// blocks laid out by C++ (std430 puts each struct at a 16-byte boundary).
struct CheckPush {
  uint count = 0, pad0 = 0, pad1 = 0, pad2 = 0;
  shared::RotationPush rotation{};
  shared::BatchArgsPush batchArgs{};
};

// What the shader writes to its contract buffer besides π, 2π and its
// workgroup size, in the shader's order (shared_layout_check.comp kContract).
struct Named {
  const char* name;
  uint value;
};
#define C(x) Named{#x, shared::x}
const std::vector<Named> kContract = {
      C(kLocalSize), C(kGpuLocalSize), C(kMinLevel), C(kFusedMaxLevel), C(kRotationMaxLevel),
      C(kRotationInputFrameBinding), C(kRotationInputObjectsBinding), C(kRotationInputIdsBinding),
      C(kRotationInputNormalsBinding), C(kRotationInputTrianglesBinding), C(kRotationInputSamplesBinding),
      C(kRotationInputShadeBinding), C(kRotationInputCounterBinding), C(kRotationInputSubIdsBinding),
      C(kRotationInputSubNormalsBinding), C(kRotationInputEdgesBinding), C(kRotationInputBindings),
      C(kResolveFrameBinding), C(kResolveIdsBinding), C(kResolveRadianceBinding), C(kResolveBackgroundBinding),
      C(kResolveEdgesBinding), C(kResolveBindings), C(kExposureFrameBinding), C(kExposureIdsBinding),
      C(kExposureRadianceBinding), C(kExposureResultBinding), C(kExposureBindings), C(kTonemapFrameBinding),
      C(kTonemapRadianceBinding), C(kTonemapRgba8Binding), C(kTonemapThresholdsBinding),
      C(kTonemapExposureBinding), C(kTonemapBindings), C(kRotateSamplesBinding), C(kRotateSlicesBinding),
      C(kRotateMethodDataBinding), C(kRotateRotatedBinding), C(kRotateBindings), C(kTripleProductShadeBinding),
      C(kTripleProductRotatedBinding), C(kTripleProductLightBinding), C(kTripleProductVisibilityBinding),
      C(kTripleProductRadianceBinding), C(kTripleProductCounterBinding), C(kTripleProductBindings),
      C(kBatchArgsCounterBinding), C(kBatchArgsArgsBinding), C(kBatchArgsBindings), C(kFusedSamplesBinding),
      C(kFusedShadeBinding), C(kFusedObjectsBinding), C(kFusedSliceTexelsBinding), C(kFusedLightTexelsBinding),
      C(kFusedVisibilityTexelsBinding), C(kFusedDirectionTexelsBinding), C(kFusedPointLightsBinding),
      C(kFusedRadianceBinding), C(kFusedCounterBinding), C(kFusedMasksBinding), C(kFusedSliceEnergyBinding),
      C(kFusedLobesBinding), C(kFusedLobeLightTexelsBinding), C(kFusedPointSliceTexelsBinding),
      C(kFusedBindings), C(kSplitsumSamplesBinding), C(kSplitsumShadeBinding), C(kSplitsumObjectsBinding),
      C(kSplitsumCounterBinding), C(kSplitsumMasksBinding), C(kSplitsumLobesBinding),
      C(kSplitsumLobeLightTexelsBinding), C(kSplitsumRadianceBinding), C(kSplitsumBindings),
      C(kGBufferPositionsBinding), C(kGBufferNormalsBinding), C(kGBufferTrianglesBinding), C(kGBufferBindings),
      C(kExposureLocalSize), C(kSpecLevel), C(kSpecThetaSamples), C(kSpecLocalSize), C(kSpecInterpolate),
      C(kSpecPrefilterFinest), C(kToneCodes)};
#undef C

glm::uvec4 packCase(uint n, uint band, uint l, uint i, uint j) { return {n, band * 256 + l, i, j}; }

float lookupInput(uint k, uint s) { return static_cast<float>((k * (7u + 2u * s) + 3u * s) % 53u) / 13.0f; }

// The C++ reading of the lookup results of case k: the four weights, then
// the point value and t.
std::array<glm::vec4, 2> expectedLookup(uint k) {
  const float t = static_cast<float>(k % 101u) / 101.0f;
  const float point = shared::pointFromMean(lookupInput(k, 0), lookupInput(k, 1), lookupInput(k, 2), lookupInput(k, 3),
                                            lookupInput(k, 4));
  return {shared::catmullRomWeights(t), glm::vec4(point, t, 0.0f, 0.0f)};
}

// The C++ reading of what the shader writes for one case.
std::array<glm::uvec4, 3> expected(const glm::uvec4& c) {
  const uint n = c.x, band = c.y >> 8, l = c.y & 255u, i = c.z, j = c.w;
  const uint key = shared::haarPreorderKey(n - 1, l, i, j);
  const shared::HaarBlock block = shared::haarPreorderBlock(n - 1, key);
  const uint quadrant = shared::haarChildQuadrant(i, j);
  const shared::vec3 sign = shared::haarChildSign(quadrant);
  const uint index = shared::haarDetailIndex(1u << n, band, l, i, j);
  const shared::HaarDetailPosition p = shared::haarDetailPosition(n, index);
  return {glm::uvec4(key, block.level, block.i, block.j),
          glm::uvec4(std::bit_cast<uint>(sign.x), std::bit_cast<uint>(sign.y), std::bit_cast<uint>(sign.z), quadrant),
          glm::uvec4(index, p.band, p.level, (p.i << 16) | p.j)};
}

GPU_TEST(SharedLayout, ShaderAndCppAgreeOnTheHaarNumbersAndTheLookup) {
  HAARCAST_REQUIRE_VULKAN();
  std::vector<glm::uvec4> cases;
  for (uint n = 1; n <= shared::kFusedMaxLevel; ++n) {
    for (uint l = 0; l < n; ++l) {
      for (uint i = 0; i < (1u << l); ++i) {
        for (uint j = 0; j < (1u << l); ++j) {
          for (uint band = 0; band < 3; ++band) cases.push_back(packCase(n, band, l, i, j));
        }
      }
    }
  }
  // Larger maps (detail index up to 2^(2n)): random blocks and the far corner.
  std::mt19937 rng(10);
  for (uint n : {8u, 10u, 12u, 15u}) {
    for (uint l = 0; l < n; ++l) {
      std::uniform_int_distribution<uint> block(0, (1u << l) - 1);
      for (int s = 0; s < 16; ++s) cases.push_back(packCase(n, static_cast<uint>(s % 3), l, block(rng), block(rng)));
      cases.push_back(packCase(n, 2, l, (1u << l) - 1, (1u << l) - 1));
    }
  }

  Context context(testing::testOptions());
  const std::size_t contractWords = 3 + kContract.size() + 8;
  Buffer in(context, cases.size() * sizeof(glm::uvec4)), out(context, 5 * cases.size() * sizeof(glm::uvec4)),
      contract(context, contractWords * sizeof(uint));
  in.upload(std::span<const glm::uvec4>(cases));
  ComputePipeline check(context, "shared_layout_check.comp", 3, sizeof(CheckPush));
  check.bind({&in, &out, &contract});
  CheckPush push;
  push.count = static_cast<uint>(cases.size());
  push.rotation = {11u, 12u, 13u, 14u};
  push.batchArgs = {21u, 22u, 23u, 24u};
  context.submit([&](VkCommandBuffer cb) {
    check.dispatch(cb, {(push.count + shared::kLocalSize - 1) / shared::kLocalSize, 1, 1}, &push, sizeof push);
    computeBarrier(cb);
  });
  std::vector<glm::uvec4> got(5 * cases.size());
  out.download(std::span<glm::uvec4>(got));

  // The interface: each number as C++ has it, then what the shader wrote.
  std::vector<Named> interface = {{"kPiF (bits)", std::bit_cast<uint>(shared::kPiF)},
                             {"kTwoPiF (bits)", std::bit_cast<uint>(shared::kTwoPiF)},
                             {"gl_WorkGroupSize.x = kLocalSize", shared::kLocalSize}};
  interface.insert(interface.end(), kContract.begin(), kContract.end());
  interface.insert(interface.end(), {{"RotationPush::first", push.rotation.first},
                           {"RotationPush::count", push.rotation.count},
                           {"RotationPush::pad0", push.rotation.pad0},
                           {"RotationPush::pad1", push.rotation.pad1},
                           {"BatchArgsPush::batch", push.batchArgs.batch},
                           {"BatchArgsPush::batches", push.batchArgs.batches},
                           {"BatchArgsPush::pad0", push.batchArgs.pad0},
                           {"BatchArgsPush::pad1", push.batchArgs.pad1}});
  ASSERT_EQ(interface.size(), contractWords);
  std::vector<uint> seen(contractWords);
  contract.download(std::span<uint>(seen));
  for (std::size_t w = 0; w < interface.size(); ++w) {
    EXPECT_EQ(seen[w], interface[w].value)
        << interface[w].name << ": GLSL " << seen[w] << ", C++ " << interface[w].value;
  }

  std::size_t wrong = 0;
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const std::array<glm::uvec4, 3> want = expected(cases[k]);
    const std::array<glm::vec4, 2> lookup = expectedLookup(static_cast<uint>(k));
    for (std::size_t r = 0; r < 2; ++r) {
      const glm::vec4 g(std::bit_cast<float>(got[5 * k + 3 + r].x), std::bit_cast<float>(got[5 * k + 3 + r].y),
                        std::bit_cast<float>(got[5 * k + 3 + r].z), std::bit_cast<float>(got[5 * k + 3 + r].w));
      for (int e = 0; e < 4; ++e) {
        if (std::abs(g[e] - lookup[r][e]) <= 1e-6f * (1.0f + std::abs(lookup[r][e]))) continue;
        if (++wrong <= 10) {
          ADD_FAILURE() << "case " << k << (r == 0 ? " Catmull-Rom weight " : " point value/t ") << e << ": GLSL "
                        << g[e] << ", C++ " << lookup[r][e];
        }
      }
    }
    for (std::size_t r = 0; r < 3; ++r) {
      if (got[5 * k + r] == want[r]) continue;
      if (++wrong <= 10) {
        const glm::uvec4& g = got[5 * k + r];
        ADD_FAILURE() << "case (n " << cases[k].x << ", band " << (cases[k].y >> 8) << ", l " << (cases[k].y & 255u)
                      << ", i " << cases[k].z << ", j " << cases[k].w << ") result " << r << ": GLSL (" << g.x << ", "
                      << g.y << ", " << g.z << ", " << g.w << "), C++ (" << want[r].x << ", " << want[r].y << ", "
                      << want[r].z << ", " << want[r].w << ")";
      }
    }
  }
  EXPECT_EQ(wrong, 0u) << "of " << 5 * cases.size() << " results";
  testing::expectNoValidationMessages(context);
}

}  // namespace
}  // namespace haarcast::gpu
