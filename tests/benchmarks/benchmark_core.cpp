// Benchmarks of the core math: the Haar transform, the four rotation methods
// (DESIGN.md "Rotation methods") and the triple product.
//
// Run:   deploy/run.sh bench -- --benchmark_filter=Rotate
//        (or build/bin/haarcast-bench --benchmark_filter=... directly)
//
// Reading the numbers. The last number in a name is the map level n (except
// BM_TripleProduct, where it is k); the "coeffs" counter is N = 4^n, the
// coefficient count. One level up multiplies N by 4, so an O(N) method takes
// ×4 time per level, O(N log N) a little more, O(N/4^k) (haar from a coarser
// start level) shifts the whole curve down. Compare methods on the same line
// of one run, not across runs (DESIGN.md "Speed": a ratio measured side by
// side). items_per_second is transforms, rotations or triple products per
// second. BM_TripleProduct is O((k_L + k_V) log N): time should grow about
// linearly in k at a fixed level.
//
// matrix and table precompute a lot (sparse matrices per elevation, pre-rotated
// copies per normal), so they stop at level 6. Every rotator is built once per
// level, outside the timed loop; a method whose construction throws is
// reported as skipped with the reason rather than aborting the run.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstddef>
#include <exception>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "haarcast/assets/procedural_environment.h"
#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/haar.h"
#include "haarcast/core/rotate_haar.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/core/triple_product.h"

namespace {

using namespace haarcast;

// Rotations are cycled from a fixed list so that every method sees the same
// ones and the random generator stays out of the timed loop.
constexpr std::size_t kRotationCount = 64;  // power of two: index with a mask

const std::vector<EulerYXY>& rotations() {
  static const std::vector<EulerYXY> list = randomRotations(kRotationCount, 20240611u);
  return list;
}

// A glossy test signal: red channel of Phong-64 slices at a few outgoing
// elevations — smooth, with a sharp lobe, like the slices haarcast stores.
std::vector<HaarMap> phongSlices(int level) {
  const auto phong = makePhong(glm::dvec3(0.1), glm::dvec3(0.9), 64.0);
  std::vector<HaarMap> slices;
  for (const double thetaOut : {0.15, 0.55, 0.95, 1.35}) {
    slices.push_back(forwardHaar(sliceMap(*phong, thetaOut, 0, level, 2)));
  }
  return slices;
}

// A smooth map with some high-frequency content for the transform benchmarks.
SphereMap testMap(int level) {
  return SphereMap::fromFunction(level, [](const glm::dvec3& d) {
    return 1.0 + 0.5 * d.y + 0.25 * std::sin(9.0 * d.x) * std::cos(5.0 * d.z) + (d.y > 0.9 ? 4.0 : 0.0);
  });
}

void setCounters(benchmark::State& state, int level) {
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations()));
  state.counters["coeffs"] = static_cast<double>(mapSize(level)) * mapSize(level);
}

// ---- Haar transform -----------------------------------------------------

void BM_ForwardHaar(benchmark::State& state) {
  const int level = static_cast<int>(state.range(0));
  const SphereMap map = testMap(level);
  for (auto _ : state) {
    HaarMap coeffs = forwardHaar(map);
    benchmark::DoNotOptimize(coeffs.coefficients().data());
    benchmark::ClobberMemory();
  }
  setCounters(state, level);
}
BENCHMARK(BM_ForwardHaar)->DenseRange(4, 7)->Unit(benchmark::kMicrosecond);

void BM_InverseHaar(benchmark::State& state) {
  const int level = static_cast<int>(state.range(0));
  const HaarMap coeffs = forwardHaar(testMap(level));
  for (auto _ : state) {
    SphereMap map = inverseHaar(coeffs);
    benchmark::DoNotOptimize(map.values().data());
    benchmark::ClobberMemory();
  }
  setCounters(state, level);
}
BENCHMARK(BM_InverseHaar)->DenseRange(4, 7)->Unit(benchmark::kMicrosecond);

// ---- Rotation -----------------------------------------------------------

// Google Benchmark calls a benchmark function several times while it settles
// the iteration count; the rotator (and a construction failure) is kept
// between those calls. One entry is enough: the runs of one (method, level)
// are consecutive, and keeping only the last bounds the memory the big
// precomputations hold.
struct CachedRotator {
  RotationMethod method = RotationMethod::Haar;
  int level = -1;
  std::unique_ptr<SliceRotator> rotator;
  std::string error;  // non-empty when construction or a first rotation threw
};

const CachedRotator& rotatorFor(RotationMethod method, int level) {
  static CachedRotator cache;
  if (cache.level == level && cache.method == method) return cache;
  cache = CachedRotator{method, level, nullptr, {}};
  try {
    cache.rotator = makeRotator(method, phongSlices(level));
    HaarMap probe;
    cache.rotator->rotate(0, rotations().front(), probe);  // fail here, not in the loop
  } catch (const std::exception& e) {
    cache.rotator.reset();
    cache.error = std::string(methodName(method)) + " at level " + std::to_string(level) + ": " + e.what();
  }
  return cache;
}

void BM_Rotate(benchmark::State& state, RotationMethod method) {
  const int level = static_cast<int>(state.range(0));
  const CachedRotator& cached = rotatorFor(method, level);
  if (!cached.rotator) {
    state.SkipWithError(cached.error.c_str());
    return;
  }
  const SliceRotator& rotator = *cached.rotator;
  const std::vector<EulerYXY>& rs = rotations();
  const std::size_t slices = rotator.sliceCount();
  HaarMap out;
  std::size_t i = 0;
  for (auto _ : state) {
    rotator.rotate(i % slices, rs[i & (kRotationCount - 1)], out);
    benchmark::DoNotOptimize(out.coefficients().data());
    benchmark::ClobberMemory();
    ++i;
  }
  setCounters(state, level);
  state.counters["stored_bytes"] = static_cast<double>(rotator.storedBytes());
}
BENCHMARK_CAPTURE(BM_Rotate, haar, RotationMethod::Haar)->DenseRange(4, 7)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Rotate, spatial, RotationMethod::Spatial)->DenseRange(4, 7)->Unit(benchmark::kMicrosecond);
// matrix keeps a sparse N×N matrix per sampled elevation and table a grid of
// pre-rotated copies per slice: their storage (the stored_bytes counter; about
// 50 MB and 10 MB at level 6 for these four slices and the default options)
// grows too fast to be worth level 7 here.
BENCHMARK_CAPTURE(BM_Rotate, matrix, RotationMethod::Matrix)->DenseRange(4, 6)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Rotate, table, RotationMethod::Table)->DenseRange(4, 6)->Unit(benchmark::kMicrosecond);

// The seed's method alone: its variants side by side (rotate_haar.h), and the
// start-level option, which drops k finest levels for O(N/4^k) work. Args:
// (level, start level or −1 for the finest).
void BM_RotateHaar(benchmark::State& state, HaarVariant variant) {
  const int level = static_cast<int>(state.range(0));
  const int start = static_cast<int>(state.range(1));
  const std::vector<HaarMap> slices = phongSlices(level);
  const HaarRotationOptions options{variant, start};
  const std::vector<EulerYXY>& rs = rotations();
  std::size_t i = 0;
  for (auto _ : state) {
    const HaarMap out = rotateHaar(slices[i % slices.size()], rs[i & (kRotationCount - 1)], options);
    benchmark::DoNotOptimize(out.coefficients().data());
    ++i;
  }
  setCounters(state, level);
}
BENCHMARK_CAPTURE(BM_RotateHaar, faithful, HaarVariant::Faithful)
    ->ArgsProduct({{4, 5, 6, 7}, {-1}})->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RotateHaar, local, HaarVariant::Local)
    ->ArgsProduct({{4, 5, 6, 7}, {-1}})->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_RotateHaar, refined, HaarVariant::Refined)
    ->Args({7, 6})->Args({7, 5})->Args({7, 4})->Args({7, 3})->Unit(benchmark::kMicrosecond);

// ---- Triple product -----------------------------------------------------

constexpr int kTripleLevel = 6;

struct TripleInputs {
  HaarMap light;        // dense L·ΔΩ, truncated per benchmark to k terms
  HaarMap brdf;         // a rotated Phong slice: dense, as per pixel
  SparseHaar visibility;  // top 64, as stored per vertex
  std::string error;
};

const TripleInputs& tripleInputs() {
  static const TripleInputs inputs = [] {
    TripleInputs in;
    try {
      in.light = forwardHaar(assets::proceduralEnvironment(kTripleLevel, 4)[0].weightedBySolidAngle());
      in.brdf = rotateSpatial(phongSlices(kTripleLevel)[1], EulerYXY{0.7, 0.9, 0.3});
      // Visibility of a point near a wall: the lower hemisphere below a
      // slanted horizon and a cone toward +X are blocked.
      const glm::dvec3 blocker = glm::normalize(glm::dvec3(1.0, 0.3, 0.2));
      const SphereMap v = supersampledMap(kTripleLevel, 2, [&](const glm::dvec3& d) {
        if (d.y < -0.1 + 0.2 * d.z) return 0.0;
        return glm::dot(d, blocker) > 0.85 ? 0.0 : 1.0;
      });
      in.visibility = keepLargest(forwardHaar(v), 64);
    } catch (const std::exception& e) {
      in.error = std::string("triple product inputs: ") + e.what();
    }
    return in;
  }();
  return inputs;
}

void BM_TripleProduct(benchmark::State& state) {
  const TripleInputs& in = tripleInputs();
  if (!in.error.empty()) {
    state.SkipWithError(in.error.c_str());
    return;
  }
  const auto k = static_cast<std::size_t>(state.range(0));
  SparseHaar light;
  try {
    light = keepLargest(in.light, k);
    benchmark::DoNotOptimize(tripleProduct(light, in.brdf, in.visibility));  // fail here, not in the loop
  } catch (const std::exception& e) {
    const std::string error = std::string("triple product: ") + e.what();
    state.SkipWithError(error.c_str());
    return;
  }
  for (auto _ : state) {
    double radiance = tripleProduct(light, in.brdf, in.visibility);
    benchmark::DoNotOptimize(radiance);
  }
  setCounters(state, kTripleLevel);
  state.counters["k_light"] = static_cast<double>(light.size());
  state.counters["k_visibility"] = static_cast<double>(in.visibility.size());
}
BENCHMARK(BM_TripleProduct)->RangeMultiplier(4)->Range(16, 4096)->Unit(benchmark::kNanosecond);

}  // namespace

BENCHMARK_MAIN();
