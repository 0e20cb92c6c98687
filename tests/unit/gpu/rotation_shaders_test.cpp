// The rotation shaders rotate_haar/table/matrix.comp against the CPU rotators
// of the same method (makeRotator(method, slices, {})), coefficient by
// coefficient, on real slice tables (Phong-64 and Lambert, coloured so that a
// channel mix-up shows), for random rotations and the pole and seam cases.
//
// What "equal to float precision" means here. The CPU rotators work in
// double and round once; the shaders work in float throughout. Each sample's
// angles are rounded to float for the GPU, so the CPU reference is given the
// same float-rounded angles: the comparison then measures arithmetic, not the
// input's rounding. The bound on |gpu − cpu| is relative to the map's largest
// |coefficient| (the error of a sum scales with its largest terms, not with
// the result); each method's bound is justified where it is defined.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <sys/resource.h>

#include "gpu_test_util.h"
#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/haar.h"
#include "haarcast/core/rotation.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/gpu/context.h"
#include "haarcast/gpu/passes.h"
#include "haarcast/gpu/rotation_data.h"

namespace haarcast::gpu {
namespace {

// The contract's binding-0 record: gpu::RotationSample (core/shared_layout.h).

using shared::RotationPush;

const char* shaderOf(RotationMethod m) {
  switch (m) {
    case RotationMethod::Haar: return "rotate_haar.comp";
    case RotationMethod::Table: return "rotate_table.comp";
    case RotationMethod::Matrix: return "rotate_matrix.comp";
    case RotationMethod::Spatial: return "rotate_spatial.comp";
    case RotationMethod::Fused: return "";  // no rotated coefficients: fused.comp (fused_pass_test.cpp)
    case RotationMethod::Splitsum: return "";  // no slices: splitsum.comp (splitsum_frame_test.cpp)
  }
  return "";
}

std::vector<BrdfSliceTable> sliceTables(int level, int thetaSamples) {
  const auto phong = makePhong({0.05, 0.1, 0.02}, {0.9, 0.6, 0.3}, 64.0);
  const auto lambert = makeLambert({0.8, 0.5, 0.2});
  const SliceTableOptions o{level, thetaSamples, 2};
  std::vector<BrdfSliceTable> out;
  out.push_back(BrdfSliceTable::build(*phong, o));
  out.push_back(BrdfSliceTable::build(*lambert, o));
  return out;
}

// One sample: object, θ slice and the rotation (already float-rounded).
struct Case {
  int object = 0;
  int theta = 0;
  EulerYXY r;
};

EulerYXY floatRounded(const EulerYXY& r) {
  return {static_cast<float>(r.alpha), static_cast<float>(r.beta), static_cast<float>(r.gamma)};
}

// Random rotations (normals uniform, spins uniform), then the poles (β = 0,
// normal straight up; β = π in float, straight down up to 9e-8 rad), the φ
// seam (α, γ = 0), whole-pixel φ-shifts, where source points fall on pixel
// centres and cell edges, and elevations outside [0, π].
//
// The table is not given β = π: there the float β is π + 9e-8, which the
// CPU, in double, reads as a rotation just off the pole and splits into α and
// γ by atan2 of 1e-7-sized numbers, while float reads it as the pole itself.
// Both are right; they pick different copies (γ's snap), as any two
// implementations would that round differently at a gimbal pole.
std::vector<Case> cases(int level, int thetaSamples, int randomCount, std::uint32_t seed, bool southPole = true) {
  std::vector<EulerYXY> rotations = randomRotations(randomCount, seed);
  const double pixel = kTwoPi / mapSize(level);
  const EulerYXY special[] = {
      // clang-format off
      {0.0, 0.0, 0.0},          {0.7, 0.0, 0.0},           {0.3, 0.0, 2.1},         {0.0, 0.9, 0.0},
      {3 * pixel, 0.5, 0.0},    {0.0, 1.7, 5 * pixel},     {kPi, kPi / 2, kPi},     {kTwoPi - 1e-4, 1.2, 0.0},
      {2 * pixel, 0.0, pixel},  {0.0, 3.0, 0.0},
      // β outside [0, π], which matrix folds back and table canonicalises.
      {0.4, -1.0, 0.2},         {1.0, 4.0, 2.0},
      // clang-format on
  };
  rotations.insert(rotations.end(), std::begin(special), std::end(special));
  if (southPole) {
    rotations.push_back({0.0, kPi, 0.0});
    rotations.push_back({1.1, kPi, 0.4});
  }
  std::vector<Case> out;
  for (std::size_t i = 0; i < rotations.size(); ++i) {
    out.push_back({static_cast<int>(i % 2), static_cast<int>((i / 2) % static_cast<std::size_t>(thetaSamples)),
                   floatRounded(rotations[i])});
  }
  return out;
}

// Binding 1: every object's slices, slice s channel c at (s·3 + c)·N.
std::vector<float> packSlices(const std::vector<BrdfSliceTable>& tables) {
  std::vector<float> out;
  for (const BrdfSliceTable& table : tables)
    for (int t = 0; t < table.thetaSamples(); ++t)
      for (int c = 0; c < 3; ++c) {
        const auto coeffs = table.slice(c, t).coefficients();
        out.insert(out.end(), coeffs.begin(), coeffs.end());
      }
  return out;
}

struct GpuRun {
  std::vector<float> rotated;  // (i·3 + c)·N
  double seconds = 0.0;        // wall time of the submits
  double cpuSeconds = 0.0;     // process CPU time (all threads) during them
};

// CPU time of the whole process, every thread: on lavapipe the "GPU" is
// this process's worker threads, so on a loaded machine this is the fairer
// figure of its work than the wall time.
double processCpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// Runs `shader` over the cases, in `batches` dispatches (so that the push
// constant `first` is exercised), and reads every dispatch's output back.
GpuRun rotateOnGpu(Context& context, RotationMethod method, const std::vector<BrdfSliceTable>& tables,
                   const std::vector<std::uint32_t>& methodData, const std::vector<std::uint32_t>& methodBase,
                   const std::vector<Case>& list, int batches = 2) {
  const int level = tables.front().level();
  const int thetaSamples = tables.front().thetaSamples();
  const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  std::vector<RotationSample> samples;
  for (const Case& c : list) {
    RotationSample s{};
    s.slice = static_cast<std::uint32_t>(c.object * thetaSamples + c.theta);
    s.methodBase = methodBase[static_cast<std::size_t>(c.object)];
    s.alpha = static_cast<float>(c.r.alpha);
    s.beta = static_cast<float>(c.r.beta);
    s.gamma = static_cast<float>(c.r.gamma);
    samples.push_back(s);
  }
  const std::vector<float> slices = packSlices(tables);
  Buffer sampleBuffer(context, samples.size() * sizeof(RotationSample));
  Buffer sliceBuffer(context, slices.size() * sizeof(float));
  Buffer dataBuffer(context, methodData.size() * sizeof(std::uint32_t));
  const std::size_t perBatch =
      (samples.size() + static_cast<std::size_t>(batches) - 1) / static_cast<std::size_t>(batches);
  Buffer outBuffer(context, perBatch * 3 * n * sizeof(float));
  sampleBuffer.upload(std::span<const RotationSample>(samples));
  sliceBuffer.upload(std::span<const float>(slices));
  dataBuffer.upload(std::span<const std::uint32_t>(methodData));

  ComputePipeline pipeline(context, shaderOf(method), shared::kRotateBindings, sizeof(RotationPush),
                           {{shared::kSpecLevel, static_cast<std::uint32_t>(level)},
                            {shared::kSpecThetaSamples, static_cast<std::uint32_t>(thetaSamples)}});
  pipeline.bind({&sampleBuffer, &sliceBuffer, &dataBuffer, &outBuffer});
  GpuRun run;
  run.rotated.assign(samples.size() * 3 * n, 0.0f);
  // llvmpipe compiles a pipeline's machine code at its first dispatch; one
  // untimed sample keeps that out of the figure.
  const RotationPush warmUp{0, 1, 0, 0};
  context.submit([&](VkCommandBuffer cb) { pipeline.dispatch(cb, {1, 3, 1}, &warmUp, sizeof warmUp); });
  for (std::size_t first = 0; first < samples.size(); first += perBatch) {
    const RotationPush push{static_cast<std::uint32_t>(first),
                            static_cast<std::uint32_t>(std::min(perBatch, samples.size() - first)), 0, 0};
    const auto start = std::chrono::steady_clock::now();
    const double cpuStart = processCpuSeconds();
    context.submit([&](VkCommandBuffer cb) { pipeline.dispatch(cb, {push.count, 3, 1}, &push, sizeof push); });
    run.cpuSeconds += processCpuSeconds() - cpuStart;
    run.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    outBuffer.download(std::span<float>(run.rotated.data() + first * 3 * n, push.count * 3 * n));
  }
  return run;
}

struct Comparison {
  double worst = 0.0;  // max over maps of max|gpu − cpu| / max|cpu|
  std::size_t worstCase = 0;
  int worstChannel = 0;
  double cpuSeconds = 0.0;  // in the CPU rotators' rotate() alone
};

// The CPU reference for every case and channel, compared with the GPU.
// rotators[object][channel].
Comparison compare(const std::vector<std::vector<const SliceRotator*>>& rotators, const std::vector<Case>& list,
                   const std::vector<float>& gpu, std::size_t n) {
  Comparison result;
  HaarMap cpu;
  for (std::size_t i = 0; i < list.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const auto start = std::chrono::steady_clock::now();
      rotators[static_cast<std::size_t>(list[i].object)][static_cast<std::size_t>(c)]->rotate(
          static_cast<std::size_t>(list[i].theta), list[i].r, cpu);
      result.cpuSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      double largest = 0.0, error = 0.0;
      const float* g = gpu.data() + (i * 3 + static_cast<std::size_t>(c)) * n;
      for (std::size_t k = 0; k < n; ++k) {
        largest = std::max(largest, std::abs(static_cast<double>(cpu[k])));
        error = std::max(error, std::abs(static_cast<double>(g[k]) - cpu[k]));
      }
      const double relative = largest > 0.0 ? error / largest : error;
      if (!(relative <= result.worst)) {  // NaN lands here too
        result.worst = relative;
        result.worstCase = i;
        result.worstChannel = c;
      }
    }
  }
  return result;
}

std::string describe(const Case& c) {
  return "object " + std::to_string(c.object) + ", θ slice " + std::to_string(c.theta) + ", (α, β, γ) = (" +
         std::to_string(c.r.alpha) + ", " + std::to_string(c.r.beta) + ", " + std::to_string(c.r.gamma) + ")";
}

struct MethodRun {
  Comparison comparison;
  GpuRun gpu;
};

// Builds CPU rotators and the packed data for both objects, runs the GPU
// and compares.
MethodRun runMethod(Context& context, RotationMethod method, int level, int thetaSamples, const std::vector<Case>& list,
                    int batches = 2, const RotatorOptions& options = {}) {
  const std::vector<BrdfSliceTable> tables = sliceTables(level, thetaSamples);
  std::vector<std::vector<std::unique_ptr<SliceRotator>>> owned(tables.size());
  std::vector<std::vector<const SliceRotator*>> rotators(tables.size());
  std::vector<std::uint32_t> methodData, methodBase;
  for (std::size_t o = 0; o < tables.size(); ++o) {
    std::array<const SliceRotator*, 3> channels{};
    for (int c = 0; c < 3; ++c) {
      owned[o].push_back(makeRotator(method, tables[o].channelSlices(c), options));
      rotators[o].push_back(owned[o].back().get());
      channels[static_cast<std::size_t>(c)] = owned[o].back().get();
    }
    const auto sliceBase = static_cast<std::uint32_t>(o * static_cast<std::size_t>(thetaSamples));
    const bool prebuilt = method == RotationMethod::Table || method == RotationMethod::Matrix;
    methodBase.push_back(prebuilt ? appendRotationData(channels, tables[o], sliceBase, methodData)
                                  : appendRotationData(method, tables[o], sliceBase, methodData, options));
  }
  MethodRun run;
  run.gpu = rotateOnGpu(context, method, tables, methodData, methodBase, list, batches);
  const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  run.comparison = compare(rotators, list, run.gpu.rotated, n);
  return run;
}

constexpr double kBound = 1e-5;  // max|gpu − cpu| / max|c|; see the note above the tests

class RotationShaders : public testing::GpuTest {
 protected:
  void SetUp() override {
    testing::GpuTest::SetUp();
    HAARCAST_REQUIRE_VULKAN();
    context_ = std::make_unique<Context>(testing::testOptions());
  }
  void TearDown() override {
    if (context_) testing::expectNoValidationMessages(*context_);
    context_.reset();  // inside the test: the fixture sees what its destruction reports
    testing::GpuTest::TearDown();
  }
  void expectEqualsCpu(RotationMethod method, int level, int thetaSamples, int randomCount, double bound,
                       const RotatorOptions& options = {}) {
    const std::vector<Case> list = cases(level, thetaSamples, randomCount, 20261121u + static_cast<unsigned>(level),
                                         method != RotationMethod::Table);
    const MethodRun run = runMethod(*context_, method, level, thetaSamples, list, 2, options);
    const Comparison& c = run.comparison;
    EXPECT_LE(c.worst, bound) << methodName(method) << " at level " << level << ": worst map is "
                              << describe(list[c.worstCase]) << ", channel " << c.worstChannel;
    std::string name(methodName(method));
    if (method == RotationMethod::Haar) name.append("/").append(variantName(options.haarVariant));
    std::printf("[ rotation ] %s level %d, T = %d, %zu samples: max |gpu − cpu| / max|c| = %.3g (bound %.1g)\n",
                name.c_str(), level, thetaSamples, list.size(), c.worst, bound);
  }
  std::unique_ptr<Context> context_;
};

// The bounds. Every shader repeats its CPU rotator's arithmetic in float:
// the same formulas in the same order, with few-ULP transcendentals
// (common/sphere.glsl). What float changes is (a) the rotation matrix and
// the source positions, off by a few ulp of π (~1e-7 rad, ~1e-6 pixel at
// level 5), which moves a coefficient by up to its sensitivity to such a
// shift: measured on the CPU itself, rotating by an angle 2.4e-7 rad off
// changes these lobes' maps by up to 3e-6·max|c| at level 5 (Phong-64 is the
// sharp one); and (b) the rounding of sums: the haar details sum up to 4^(n−l)
// boundary differences with weights ≤ 2^(n−l) and divide by the side, the
// shifts and sparse products a few dozen terms, a few ulp of the largest
// term each. Measured worst cases: haar 2.9e-6, table 1.7e-6, matrix
// 1.7e-6 (levels 3–5). The bound 1e-5 leaves 3× for other devices and is
// far below what a wrong formula does: a wrong sign, band or copy is O(1),
// a missed cell, a wrong anchor or a wrong blend ≥ 1e-3·max|c| on these lobes.
TEST_F(RotationShaders, HaarEqualsCpuRefinedAtLevel3) { expectEqualsCpu(RotationMethod::Haar, 3, 3, 40, kBound); }
TEST_F(RotationShaders, HaarEqualsCpuRefinedAtLevel4) { expectEqualsCpu(RotationMethod::Haar, 4, 4, 40, kBound); }
TEST_F(RotationShaders, HaarEqualsCpuRefinedAtLevel5) { expectEqualsCpu(RotationMethod::Haar, 5, 2, 24, kBound); }

// The seed's own variant reads f's derivatives at the source points and
// multiplies them by the Jacobian of the source mapping, which carries 1/ρ
// and 1/ρ² (ρ = the source point's distance from the poles' axis): float
// rounding of the source direction is amplified near the source poles, which
// no such path avoids. Measured worst: 1.3e-5 (level 3), 4.5e-6 (level 5);
// the bound keeps the same 3× margin.
constexpr double kFaithfulBound = 4e-5;

RotatorOptions faithful() {
  RotatorOptions o;
  o.haarVariant = HaarVariant::Faithful;
  return o;
}
TEST_F(RotationShaders, HaarEqualsCpuFaithfulAtLevel3) {
  expectEqualsCpu(RotationMethod::Haar, 3, 2, 40, kFaithfulBound, faithful());
}
TEST_F(RotationShaders, HaarEqualsCpuFaithfulAtLevel5) {
  expectEqualsCpu(RotationMethod::Haar, 5, 2, 24, kFaithfulBound, faithful());
}

// The smallest maps: a 2×2 map has one block and no coarser fields, a 4×4
// map one coarser level; the index arithmetic has its edge cases there.
TEST_F(RotationShaders, EveryMethodEqualsCpuAtLevels1And2) {
  for (int level : {1, 2}) {
    expectEqualsCpu(RotationMethod::Haar, level, 2, 16, kBound);
    expectEqualsCpu(RotationMethod::Haar, level, 2, 16, kFaithfulBound, faithful());
    expectEqualsCpu(RotationMethod::Table, level, 2, 16, kBound);
    expectEqualsCpu(RotationMethod::Matrix, level, 2, 16, kBound);
  }
}

// Level 6: the shared-memory limit (haar 10.7 KiB, table and matrix 16 KiB).
TEST_F(RotationShaders, HaarEqualsCpuRefinedAtLevel6) { expectEqualsCpu(RotationMethod::Haar, 6, 1, 6, kBound); }

TEST_F(RotationShaders, TableEqualsCpuAtLevel4) { expectEqualsCpu(RotationMethod::Table, 4, 2, 40, kBound); }
TEST_F(RotationShaders, TableEqualsCpuAtLevel5) { expectEqualsCpu(RotationMethod::Table, 5, 2, 24, kBound); }

TEST_F(RotationShaders, TableEqualsCpuAtLevel6) { expectEqualsCpu(RotationMethod::Table, 6, 1, 6, kBound); }

TEST_F(RotationShaders, MatrixEqualsCpuAtLevel4) { expectEqualsCpu(RotationMethod::Matrix, 4, 2, 40, kBound); }
TEST_F(RotationShaders, MatrixEqualsCpuAtLevel5) { expectEqualsCpu(RotationMethod::Matrix, 5, 2, 24, kBound); }
TEST_F(RotationShaders, MatrixEqualsCpuAtLevel6) { expectEqualsCpu(RotationMethod::Matrix, 6, 1, 6, kBound); }

// ---- The packing of binding 2 (no device needed) ---------------------------

std::vector<BrdfSliceTable> smallTables() { return sliceTables(3, 2); }

float wordAsFloat(std::uint32_t w) { return std::bit_cast<float>(w); }

GPU_TEST(RotationData, HaarBlockHoldsTheSliceBaseAndEveryPixelDifference) {
  const BrdfSliceTable table = smallTables().front();
  const int m = mapSize(3);
  std::vector<std::uint32_t> data(5, 7u);  // an earlier object's block
  const std::uint32_t base = appendRotationData(RotationMethod::Haar, table, 11u, data);
  EXPECT_EQ(base, 5u);
  ASSERT_EQ(data.size(), 5u + 4u + 2u * 3u * static_cast<std::size_t>((2 * m - 1) * m));
  EXPECT_EQ(data[base], 11u);
  // Against the pixels themselves, not the formulas that made them.
  for (int t = 0; t < 2; ++t)
    for (int c = 0; c < 3; ++c) {
      const SphereMap f = inverseHaar(table.slice(c, t));
      const std::size_t fT = base + 4u + static_cast<std::size_t>((t * 3 + c) * (2 * m - 1) * m);
      const std::size_t fP = fT + static_cast<std::size_t>((m - 1) * m);
      for (int r = 0; r < m; ++r)
        for (int q = 0; q < m; ++q) {
          const double scale = std::max(1.0, std::abs(static_cast<double>(f.at(r, q))));
          if (r + 1 < m) {
            EXPECT_NEAR(wordAsFloat(data[fT + static_cast<std::size_t>(r * m + q)]), f.at(r + 1, q) - f.at(r, q),
                        1e-5 * scale);
          }
          EXPECT_NEAR(wordAsFloat(data[fP + static_cast<std::size_t>(r * m + q)]), f.at(r, (q + 1) % m) - f.at(r, q),
                      1e-5 * scale);
        }
    }
}

GPU_TEST(RotationData, TableBlockHoldsTheCpuRotatorsCopies) {
  const BrdfSliceTable table = smallTables().back();
  RotatorOptions o;
  o.tableElevations = 3;
  o.tableSpins = 4;
  std::vector<std::uint32_t> data;
  const std::uint32_t base = appendRotationData(RotationMethod::Table, table, 2u, data, o);
  ASSERT_EQ(data.size(), 4u + 2u * 3u * 3u * 4u * 64u);
  EXPECT_EQ(data[base], 2u);
  EXPECT_EQ(data[base + 1], 3u);
  EXPECT_EQ(data[base + 2], 4u);
  // Slice t = 1, channel 2, copy (k, j) = (2, 3).
  const auto cpu = makeRotator(RotationMethod::Table, table.channelSlices(2), o);
  const HaarMap& copy = tableCopies(*cpu).copies[(1 * 3 + 2) * 4 + 3];
  const std::size_t at = base + 4u + ((((1u * 3u + 2u) * 3u + 2u) * 4u + 3u) * 64u);
  for (std::size_t k = 0; k < 64; ++k) EXPECT_EQ(wordAsFloat(data[at + k]), copy[k]) << k;
}

GPU_TEST(RotationData, MatrixBlockHoldsTheCpuRotatorsMatrices) {
  const BrdfSliceTable table = smallTables().front();
  RotatorOptions o;
  o.matrixElevations = 3;
  std::vector<std::uint32_t> data(3, 0u);
  const std::uint32_t base = appendRotationData(RotationMethod::Matrix, table, 0u, data, o);
  EXPECT_EQ(base, 3u);
  EXPECT_EQ(data[base], 3u);
  const auto cpu = makeRotator(RotationMethod::Matrix, table.channelSlices(0), o);
  const std::vector<SparseMatrixView> matrices = elevationMatrixViews(*cpu);
  ASSERT_EQ(matrices.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    const std::size_t at = base + data[base + 4 + k];
    for (std::size_t r = 0; r <= 64; ++r) ASSERT_EQ(data[at + r], matrices[k].rowStart[r]);
    for (std::size_t e = 0; e < matrices[k].value.size(); ++e) {
      ASSERT_EQ(data[at + 65 + 2 * e], matrices[k].column[e]);
      ASSERT_EQ(wordAsFloat(data[at + 65 + 2 * e + 1]), matrices[k].value[e]);
    }
  }
  EXPECT_EQ(data.size(), base + data[base + 4 + 2] + 65 + 2 * matrices[2].value.size());
}

// Each error names what was wrong.
template <typename F>
void expectInvalid(F f, const std::string& expected) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected one mentioning \"" << expected << "\"";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

GPU_TEST(RotationData, RefusesWhatTheShadersDoNotImplement) {
  const BrdfSliceTable table = smallTables().front();
  std::vector<std::uint32_t> data;
  RotatorOptions local;
  local.haarVariant = HaarVariant::Local;
  expectInvalid([&] { appendRotationData(RotationMethod::Haar, table, 0u, data, local); }, "not local");
  RotatorOptions coarse;
  coarse.haarStartLevel = 1;
  expectInvalid([&] { appendRotationData(RotationMethod::Haar, table, 0u, data, coarse); }, "not 1");
  const BrdfSliceTable fine = BrdfSliceTable::build(*makeLambert({1.0, 1.0, 1.0}), SliceTableOptions{7, 1, 1});
  expectInvalid([&] { appendRotationData(RotationMethod::Haar, fine, 0u, data); }, "level 7");
  const auto haar = makeRotator(RotationMethod::Haar, table.channelSlices(0));
  expectInvalid([&] { appendRotationData({haar.get(), haar.get(), haar.get()}, table, 0u, data); }, "not haar");
  expectInvalid([&] { (void)tableCopies(*haar); }, "haar, not table");
  expectInvalid([&] { (void)elevationMatrixViews(*haar); }, "haar, not matrix");
  EXPECT_TRUE(data.empty());
}

// Speed, side by side in one run (machines are noisy): GPU wall time of one
// dispatch over all samples (submit and wait included) against the CPU
// rotator on one thread, per rotated map (one sample × one channel). A
// printed figure, not an assertion. HAARCAST_ROTATION_TIMING_SAMPLES sets the
// sample count (default 128 to keep CI short; the report used 4096).
TEST_F(RotationShaders, TimesEachMethodAgainstTheCpuRotator) {
  int count = 128;
  if (const char* env = std::getenv("HAARCAST_ROTATION_TIMING_SAMPLES")) count = std::max(1, std::atoi(env));
  constexpr int kLevel = 5;
  std::printf("[ rotation ] device: %s\n", context_->info().name.c_str());
  for (RotationMethod method :
       {RotationMethod::Spatial, RotationMethod::Haar, RotationMethod::Table, RotationMethod::Matrix}) {
    std::vector<Case> list = cases(kLevel, 2, count, 7u, false);
    list.resize(static_cast<std::size_t>(count));
    const MethodRun run = runMethod(*context_, method, kLevel, 2, list, 1);
    const double maps = 3.0 * static_cast<double>(count);
    std::printf(
        "[ rotation ] %-7s level %d, %d samples × 3 channels: gpu %.1f µs/map wall (%.1f µs CPU time), "
        "cpu rotator %.1f µs/map (cpu/gpu wall %.2f)\n",
        std::string(methodName(method)).c_str(), kLevel, count, run.gpu.seconds / maps * 1e6,
        run.gpu.cpuSeconds / maps * 1e6, run.comparison.cpuSeconds / maps * 1e6,
        run.comparison.cpuSeconds / run.gpu.seconds);
    // spatial (rotate_spatial.comp) is timed here for reference; its
    // accuracy is tested with the shader's own tests.
    if (method != RotationMethod::Spatial) {
      EXPECT_LE(run.comparison.worst, kBound) << methodName(method);
    }
  }
}

}  // namespace
}  // namespace haarcast::gpu
