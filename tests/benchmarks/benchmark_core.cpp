// Benchmarks of the core math: the Haar transform, the four rotation methods
// (DESIGN.md "Rotation methods"), the triple product, and one pixel's `haar`
// shading (the renderer's per-pixel work, old and lean paths side by side).
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

#include <array>
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
#include "haarcast/core/fused.h"
#include "haarcast/core/fused_cells.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/haar.h"
#include "haarcast/core/rotate_haar.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/core/triple_product.h"
#include "haarcast/core/visibility_bits.h"

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

// ---- One pixel's haar shading ----------------------------------------------
//
// What CpuRenderer does per covered pixel with the `haar` method, side by side
// with the lean path of the same library (DESIGN.md "Speed": one run):
//  * old:  per channel, SliceRotator::rotate (rotateHaar) and three
//          tripleProduct calls, one per vertex of the triangle, blended with
//          the barycentrics — 3 rotations, 9 triple products;
//  * lean: RgbHaarRotator::rotate (rotateHaar3: the geometry once for the
//          three channels, no allocation), mergeVisibility (the blend before
//          the product, which is linear in V), the merged visibility prepared
//          once, and one tripleProduct per channel with the frame's
//          PreparedLight — 1 rotation of three channels, 3 triple products.
// Inputs as the renderer has them: Phong-64 slices of the three channels,
// the light's k = 256 largest coefficients per channel, each vertex's 64
// largest visibility coefficients. Arg: the map level. Compare the two on the
// same line; the time is per pixel.
struct PixelInputs {
  int level = -1;
  std::array<std::unique_ptr<SliceRotator>, 3> rotators;  // old
  std::unique_ptr<RgbHaarRotator> rgb;                     // lean
  PixelSlices pixelSlices;                                 // fused
  FusedLight fusedLight;
  // fused by cells (shared_cells.h): the slices with their detail maps, the
  // light by cells at the default tolerance (levels ≥ kCellMinLevel).
  PixelSlices cellSlices;
  FusedLight cellLight;
  std::array<SparseHaar, 3> light;
  std::array<PreparedLight, 3> preparedLight;
  std::vector<std::array<SparseHaar, 3>> triangles;  // per-vertex visibility
  // The same visibility as the renderer's bits (visibility_bits.h): map
  // direction i at bit i % 32 of word i / 32.
  std::vector<std::array<std::vector<std::uint32_t>, 3>> triangleBits;
  std::vector<std::array<double, 3>> barycentrics;
};

constexpr std::size_t kTriangleCount = 16;  // power of two: index with a mask

const PixelInputs& pixelInputs(int level) {
  static PixelInputs in;
  if (in.level == level) return in;
  in = PixelInputs{};
  in.level = level;
  const auto phong = makePhong(glm::dvec3(0.1, 0.2, 0.3), glm::dvec3(0.9, 0.6, 0.4), 64.0);
  std::array<std::vector<HaarMap>, 3> slices;
  for (int c = 0; c < 3; ++c)
    for (const double thetaOut : {0.15, 0.55, 0.95, 1.35})
      slices[static_cast<std::size_t>(c)].push_back(forwardHaar(sliceMap(*phong, thetaOut, c, level, 2)));
  for (std::size_t c = 0; c < 3; ++c) in.rotators[c] = makeRotator(RotationMethod::Haar, slices[c]);
  in.rgb = std::make_unique<RgbHaarRotator>(slices);
  {
    std::vector<double> thetaOut;
    std::vector<HaarMap> all;
    for (std::size_t t = 0; t < slices[0].size(); ++t) thetaOut.push_back((static_cast<double>(t) + 0.5) * (kPi / 2.0) / static_cast<double>(slices[0].size()));
    for (const auto& channel : slices) all.insert(all.end(), channel.begin(), channel.end());
    const BrdfSliceTable table = BrdfSliceTable::fromSlices(thetaOut, std::move(all));
    in.pixelSlices = PixelSlices::synthesize(table);
    if (level >= static_cast<int>(shared::kCellMinLevel)) in.cellSlices = PixelSlices::synthesize(table, nullptr, true);
  }
  const std::array<SphereMap, 3> env = assets::proceduralEnvironment(level, 4);
  std::array<SphereMap, 3> weighted;
  for (std::size_t c = 0; c < 3; ++c) {
    weighted[c] = env[c].weightedBySolidAngle();
    in.light[c] = keepLargest(forwardHaar(weighted[c]), 256);
    in.preparedLight[c].assign(in.light[c]);
  }
  in.fusedLight = FusedLight::synthesize(in.light);
  if (level >= static_cast<int>(shared::kCellMinLevel)) in.cellLight = FusedLight::fromWeightedMaps(weighted, shared::kDefaultSumTolerance);
  // Each vertex near a wall: a slanted horizon and a cone-shaped occluder
  // whose direction and size vary from vertex to vertex.
  std::mt19937 rng(77);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (std::size_t t = 0; t < kTriangleCount; ++t) {
    std::array<SparseHaar, 3> vertices;
    std::array<std::vector<std::uint32_t>, 3> bits;
    for (SparseHaar& v : vertices) {
      const glm::dvec3 blocker = glm::normalize(glm::dvec3(1.0, 0.3 * u(rng), 0.5 * u(rng)));
      const double cone = 0.8 + 0.1 * u(rng), tilt = 0.2 * u(rng);
      const SphereMap map = supersampledMap(level, 2, [&](const glm::dvec3& d) {
        if (d.y < -0.1 + tilt * d.z) return 0.0;
        return glm::dot(d, blocker) > cone ? 0.0 : 1.0;
      });
      v = keepLargest(forwardHaar(map), 64);
      std::vector<std::uint32_t>& words = bits[static_cast<std::size_t>(&v - vertices.data())];
      words.assign((map.values().size() + 31) / 32, 0u);
      for (std::size_t i = 0; i < map.values().size(); ++i)
        if (map.values()[i] > 0.5f) words[i / 32] |= 1u << (i % 32);
    }
    in.triangles.push_back(std::move(vertices));
    in.triangleBits.push_back(std::move(bits));
    const double a = 0.5 * (u(rng) + 1.0), b = 0.5 * (1.0 - a) * (u(rng) + 1.0);
    in.barycentrics.push_back({a, b, 1.0 - a - b});
  }
  return in;
}

void BM_HaarPixel(benchmark::State& state, bool lean) {
  const int level = static_cast<int>(state.range(0));
  const PixelInputs& in = pixelInputs(level);
  const std::vector<EulerYXY>& rs = rotations();
  const std::size_t slices = in.rgb->sliceCount();
  HaarMap rotated;
  std::array<HaarMap, 3> rotated3;
  HaarRotationScratch scratch;
  SparseHaar merged;
  PreparedVisibility visibility;
  double radiance = 0.0;
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t slice = i % slices;
    const EulerYXY& r = rs[i & (kRotationCount - 1)];
    const std::array<SparseHaar, 3>& v = in.triangles[i & (kTriangleCount - 1)];
    const std::array<double, 3>& b = in.barycentrics[i & (kTriangleCount - 1)];
    if (lean) {
      in.rgb->rotate(slice, r, rotated3, scratch);
      mergeVisibility({&v[0], &v[1], &v[2]}, b, merged);
      visibility.assign(merged, "visibility");
      for (std::size_t c = 0; c < 3; ++c) radiance += tripleProduct(in.preparedLight[c], rotated3[c], visibility);
    } else {
      for (std::size_t c = 0; c < 3; ++c) {
        in.rotators[c]->rotate(slice, r, rotated);
        for (std::size_t k = 0; k < 3; ++k) radiance += b[k] * tripleProduct(in.light[c], rotated, v[k]);
      }
    }
    benchmark::DoNotOptimize(radiance);
    ++i;
  }
  setCounters(state, level);
  state.counters["k_light"] = static_cast<double>(in.light[0].size());
  state.counters["k_visibility"] = static_cast<double>(in.triangles[0][0].size());
}
BENCHMARK_CAPTURE(BM_HaarPixel, old, false)->DenseRange(4, 5)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_HaarPixel, lean, true)->DenseRange(4, 5)->Unit(benchmark::kMicrosecond);

// The same pixel by `fused` (fused.h): one pass over the map directions for
// the three channels, θₒ blend of two slices, the same inputs. Compare with
// BM_HaarPixel on the same run. `bits`: the visibility as the renderer holds
// it, each vertex's bits blended inside the pass (BM_FusedPixelBits); else
// the vertices' Haar lists merged and synthesised per pixel. `cells`: with
// bits, summed by cells as the renderer sums its objects by default
// (BM_FusedPixelCells; each vertex's cell masks built once, as the renderer
// keeps them).
void fusedPixel(benchmark::State& state, bool bits, bool cells = false) {
  const int level = static_cast<int>(state.range(0));
  const PixelInputs& in = pixelInputs(level);
  const std::vector<EulerYXY>& rs = rotations();
  const auto slices = static_cast<shared::uint>(in.pixelSlices.thetaSamples());
  FusedScratch scratch;
  // Per triangle, its vertices' cell masks (fused_cells.h cellMasks).
  std::vector<std::array<std::vector<std::uint32_t>, 3>> masks(kTriangleCount);
  if (cells) {
    for (std::size_t t = 0; t < kTriangleCount; ++t) {
      for (std::size_t v = 0; v < 3; ++v) {
        masks[t][v].resize(2 * cellMaskWords(level));
        cellMasks(in.triangleBits[t][v].data(), level, masks[t][v].data());
      }
    }
  }
  float radiance = 0.0f;
  std::size_t i = 0, directions = 0;
  for (auto _ : state) {
    const EulerYXY& r = rs[i & (kRotationCount - 1)];
    const std::size_t t = i & (kTriangleCount - 1);
    const std::array<double, 3>& b = in.barycentrics[t];
    const auto first = static_cast<shared::uint>(i % slices);
    const shared::SliceBlend blend{first, std::min(first + 1u, slices - 1u), 0.5f};
    std::array<float, 3> rgb{};
    if (bits) {
      const auto& words = in.triangleBits[t];
      std::array<WeightedBits, 3> vis{WeightedBits{words[0].data(), static_cast<float>(b[0])},
                                      WeightedBits{words[1].data(), static_cast<float>(b[1])},
                                      WeightedBits{words[2].data(), static_cast<float>(b[2])}};
      if (cells) {
        for (std::size_t v = 0; v < 3; ++v) vis[v].cells = masks[t][v].data();
        rgb = fusedShade(in.cellSlices, blend, r, in.cellLight, vis, {}, 0u, scratch);
      } else {
        rgb = fusedShade(in.pixelSlices, blend, r, in.fusedLight, vis, {}, 0u, scratch);
      }
      directions += scratch.passDirections;
    } else {
      const std::array<SparseHaar, 3>& v = in.triangles[t];
      const std::array<WeightedVisibility, 3> vis{WeightedVisibility{&v[0], static_cast<float>(b[0])},
                                                  WeightedVisibility{&v[1], static_cast<float>(b[1])},
                                                  WeightedVisibility{&v[2], static_cast<float>(b[2])}};
      rgb = fusedShade(in.pixelSlices, blend, r, in.fusedLight, vis, scratch);
    }
    radiance += rgb[0] + rgb[1] + rgb[2];
    benchmark::DoNotOptimize(radiance);
    ++i;
  }
  setCounters(state, level);
  if (bits) state.counters["directions"] = benchmark::Counter(static_cast<double>(directions) / static_cast<double>(std::max<std::size_t>(i, 1)));
  state.SetLabel(fusedTargetName());
}
void BM_FusedPixel(benchmark::State& state) { fusedPixel(state, false); }
void BM_FusedPixelBits(benchmark::State& state) { fusedPixel(state, true); }
void BM_FusedPixelCells(benchmark::State& state) { fusedPixel(state, true, true); }
BENCHMARK(BM_FusedPixel)->DenseRange(4, 7)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FusedPixelBits)->DenseRange(4, 7)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FusedPixelCells)->DenseRange(5, 7)->Unit(benchmark::kMicrosecond);

// The lean pixel's parts on their own: where its time goes (merge_visibility
// includes preparing the merged list, once per pixel).
void BM_HaarPixelPart(benchmark::State& state, int part) {
  const int level = static_cast<int>(state.range(0));
  const PixelInputs& in = pixelInputs(level);
  const std::vector<EulerYXY>& rs = rotations();
  std::array<HaarMap, 3> rotated3;
  HaarRotationScratch scratch;
  in.rgb->rotate(0, rs[0], rotated3, scratch);
  SparseHaar merged;
  PreparedVisibility visibility;
  double radiance = 0.0;
  std::size_t i = 0;
  for (auto _ : state) {
    const std::array<SparseHaar, 3>& v = in.triangles[i & (kTriangleCount - 1)];
    switch (part) {
      case 0: in.rgb->rotate(i % in.rgb->sliceCount(), rs[i & (kRotationCount - 1)], rotated3, scratch); break;
      case 1:
        mergeVisibility({&v[0], &v[1], &v[2]}, in.barycentrics[i & (kTriangleCount - 1)], merged);
        visibility.assign(merged, "visibility");
        break;
      default:
        if (i == 0) {
          mergeVisibility({&v[0], &v[1], &v[2]}, in.barycentrics[0], merged);
          visibility.assign(merged, "visibility");
        }
        for (std::size_t c = 0; c < 3; ++c) radiance += tripleProduct(in.preparedLight[c], rotated3[c], visibility);
    }
    benchmark::DoNotOptimize(radiance);
    benchmark::ClobberMemory();
    ++i;
  }
  setCounters(state, level);
}
BENCHMARK_CAPTURE(BM_HaarPixelPart, rotate3, 0)->DenseRange(4, 5)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_HaarPixelPart, merge_visibility, 1)->DenseRange(4, 5)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_HaarPixelPart, triple_products, 2)->DenseRange(4, 5)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
