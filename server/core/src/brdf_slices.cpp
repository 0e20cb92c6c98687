// The unrotated BRDF slice table and the supersampled map builders it uses.
#include "haarcast/core/brdf_slices.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "haarcast/core/parallel.h"

namespace haarcast {
namespace {

// Bounds shared by the table options and every supersampled builder: 1024 θₒ
// samples at level 12 would already be 200 GiB, and 64² samples per pixel is
// far past the point where the pixel means stop changing in float.
constexpr int kMaxThetaSamples = 1024;
constexpr int kMaxSupersampling = 64;

void checkSupersampling(int n, const char* what) {
  if (n < 1 || n > kMaxSupersampling) {
    throw std::invalid_argument(std::string(what) + ": supersampling " + std::to_string(n) + " is outside [1, " +
                                std::to_string(kMaxSupersampling) + "]");
  }
}

// The one definition of where a pixel's samples lie and how they are
// averaged. Positions: an n×n grid stratified uniformly in θ and φ within the
// pixel. Weights: sin θ, normalised over the pixel, so that the value is the
// solid-angle mean of f over the pixel — the quantity that SphereMap::integral's
// exact pixel solid angles assume. With uniform weights instead, a feature near
// one edge of a pixel would be counted with the wrong area (by up to
// ±(π/2M)·cot θ, i.e. ±7% at level 4 for a sun at 35° elevation). With these
// weights, SphereMap::integral of the map is the sin θ-weighted midpoint rule
// on the whole (Mn)² sample grid times 2 sin(δ/2)/δ (δ the sample spacing in
// θ), so it depends on the sample grid only, not on how it is cut into pixels.
//
// `sample(dir)` is called once per sample, in one fixed order (pixels in
// raster order, each pixel's n×n θ-major: what supersampledDirections lists);
// `store(row, col, mean)` receives the pixel's weighted mean.
template <typename T, typename Sample, typename Store>
void forEachPixelMean(int level, int n, const Sample& sample, const Store& store) {
  const int m = mapSize(level);
  const double dTheta = kPi / m / n;
  const double dPhi = kTwoPi / m / n;
  std::vector<double> sinT(static_cast<std::size_t>(n));
  std::vector<double> cosT(static_cast<std::size_t>(n));
  std::vector<double> sinP(static_cast<std::size_t>(m) * static_cast<std::size_t>(n));
  std::vector<double> cosP(sinP.size());
  for (std::size_t k = 0; k < sinP.size(); ++k) {
    const double phi = (static_cast<double>(k) + 0.5) * dPhi;
    sinP[k] = std::sin(phi);
    cosP[k] = std::cos(phi);
  }
  for (int row = 0; row < m; ++row) {
    double weightSum = 0.0;
    for (int a = 0; a < n; ++a) {
      const double theta = (row * n + a + 0.5) * dTheta;
      sinT[static_cast<std::size_t>(a)] = std::sin(theta);
      cosT[static_cast<std::size_t>(a)] = std::cos(theta);
      weightSum += sinT[static_cast<std::size_t>(a)];
    }
    weightSum *= n;
    for (int col = 0; col < m; ++col) {
      T acc{};
      for (int a = 0; a < n; ++a) {
        const double st = sinT[static_cast<std::size_t>(a)];
        const double ct = cosT[static_cast<std::size_t>(a)];
        T rowAcc{};
        const std::size_t first = static_cast<std::size_t>(col) * static_cast<std::size_t>(n);
        for (std::size_t k = first; k < first + static_cast<std::size_t>(n); ++k) {
          // sphericalToDirection with the sines and cosines precomputed.
          rowAcc += sample(glm::dvec3(st * sinP[k], ct, st * cosP[k]));
        }
        acc += rowAcc * st;
      }
      store(row, col, acc / weightSum);
    }
  }
}

// All three channels of the slice at θₒ in one pass (one BRDF evaluation per sample).
std::array<SphereMap, 3> sliceMapsRgb(const Brdf& brdf, double thetaOut, int level, int n) {
  const glm::dvec3 wo = sphericalToDirection(thetaOut, 0.0);
  std::array<SphereMap, 3> maps{SphereMap(level), SphereMap(level), SphereMap(level)};
  forEachPixelMean<glm::dvec3>(
      level, n,
      [&](const glm::dvec3& wi) {
        // ρ(ωᵢ, ωₒ)·max(cos θᵢ, 0): the slice is the reflected-radiance kernel.
        return wi.y > 0.0 ? brdf.evaluate(wi, wo) * wi.y : glm::dvec3(0.0);
      },
      [&](int row, int col, const glm::dvec3& mean) {
        for (int c = 0; c < 3; ++c) maps[static_cast<std::size_t>(c)].at(row, col) = static_cast<float>(mean[c]);
      });
  return maps;
}

}  // namespace

SphereMap supersampledMap(int level, int supersampling, const std::function<double(const glm::dvec3&)>& f) {
  checkLevel(level, "supersampledMap");
  checkSupersampling(supersampling, "supersampledMap");
  SphereMap map(level);
  forEachPixelMean<double>(level, supersampling, f,
                           [&](int row, int col, double mean) { map.at(row, col) = static_cast<float>(mean); });
  return map;
}

std::vector<glm::dvec3> supersampledDirections(int level, int supersampling) {
  checkLevel(level, "supersampledDirections");
  checkSupersampling(supersampling, "supersampledDirections");
  const std::size_t side = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(supersampling);
  std::vector<glm::dvec3> directions;
  directions.reserve(side * side);
  // The builder's own directions, in the order it asks for them.
  forEachPixelMean<double>(level, supersampling, [&](const glm::dvec3& d) {
    directions.push_back(d);
    return 0.0;
  }, [](int, int, double) {});
  return directions;
}

SphereMap supersampledMeans(int level, int supersampling, std::span<const double> values) {
  checkLevel(level, "supersampledMeans");
  checkSupersampling(supersampling, "supersampledMeans");
  const std::size_t side = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(supersampling);
  if (values.size() != side * side) {
    throw std::invalid_argument("supersampledMeans: " + std::to_string(values.size()) + " values for " +
                                std::to_string(side * side) + " samples");
  }
  SphereMap map(level);
  // forEachPixelMean asks for the samples in supersampledDirections' order,
  // so the next value is always the one for the direction it passes.
  std::size_t next = 0;
  forEachPixelMean<double>(level, supersampling, [&](const glm::dvec3&) { return values[next++]; },
                           [&](int row, int col, double mean) { map.at(row, col) = static_cast<float>(mean); });
  return map;
}

SphereMap sliceMap(const Brdf& brdf, double thetaOut, int channel, int level, int supersampling) {
  if (channel < 0 || channel >= BrdfSliceTable::kChannels) {
    throw std::invalid_argument("sliceMap: channel " + std::to_string(channel) + " is outside [0, 3)");
  }
  const glm::dvec3 wo = sphericalToDirection(thetaOut, 0.0);
  return supersampledMap(level, supersampling, [&](const glm::dvec3& wi) {
    return wi.y > 0.0 ? brdf.evaluate(wi, wo)[channel] * wi.y : 0.0;
  });
}

int BrdfSliceTable::nearestSlice(double thetaOut) const {
  const int t = thetaSamples();
  if (t == 0) throw std::logic_error("BrdfSliceTable::nearestSlice: the table is empty");
  // Samples sit at the centres of T equal cells of [0, π/2], so the nearest
  // sample is the one whose cell holds θₒ.
  const double clamped = std::clamp(thetaOut, 0.0, kPi / 2.0);
  const int cell = static_cast<int>(std::floor(clamped / (kPi / 2.0) * t));
  return std::clamp(cell, 0, t - 1);
}

const HaarMap& BrdfSliceTable::slice(int channel, int t) const {
  if (channel < 0 || channel >= kChannels || t < 0 || t >= thetaSamples()) {
    throw std::out_of_range("BrdfSliceTable::slice: (channel " + std::to_string(channel) + ", t " +
                            std::to_string(t) + ") is outside 3 × " + std::to_string(thetaSamples()));
  }
  return slices_[static_cast<std::size_t>(channel * thetaSamples() + t)];
}

std::vector<HaarMap> BrdfSliceTable::channelSlices(int channel) const {
  std::vector<HaarMap> out;
  out.reserve(static_cast<std::size_t>(thetaSamples()));
  for (int t = 0; t < thetaSamples(); ++t) out.push_back(slice(channel, t));
  return out;
}

std::size_t BrdfSliceTable::storedBytes() const {
  std::size_t bytes = 0;
  for (const HaarMap& s : slices_) bytes += s.coefficientCount() * sizeof(float);
  return bytes;
}

// Work is split by θₒ sample: each task evaluates the BRDF once per sample for
// all three channels and Haar-codes the three maps, on parallelFor's threads;
// progress(done, T) runs on the calling thread, in order, so a callback needs
// no locking and an exception from it stops the build cleanly.
BrdfSliceTable BrdfSliceTable::build(const Brdf& brdf, const SliceTableOptions& options,
                                     const std::function<void(int, int)>& progress) {
  checkLevel(options.level, "SliceTableOptions.level");
  if (options.thetaSamples < 1 || options.thetaSamples > kMaxThetaSamples) {
    throw std::invalid_argument("SliceTableOptions.thetaSamples: " + std::to_string(options.thetaSamples) +
                                " is outside [1, " + std::to_string(kMaxThetaSamples) + "]");
  }
  checkSupersampling(options.supersampling, "SliceTableOptions.supersampling");

  const int total = options.thetaSamples;
  BrdfSliceTable table;
  table.level_ = options.level;
  table.thetaOut_.resize(static_cast<std::size_t>(total));
  for (int t = 0; t < total; ++t) table.thetaOut_[static_cast<std::size_t>(t)] = (t + 0.5) * (kPi / 2.0) / total;
  table.slices_.resize(static_cast<std::size_t>(kChannels * total));

  parallelFor(
      static_cast<std::size_t>(total),
      [&](std::size_t i) {
        const int t = static_cast<int>(i);
        const std::array<SphereMap, 3> maps =
            sliceMapsRgb(brdf, table.thetaOut(t), options.level, options.supersampling);
        for (int c = 0; c < kChannels; ++c) {
          table.slices_[static_cast<std::size_t>(c * total + t)] = forwardHaar(maps[static_cast<std::size_t>(c)]);
        }
      },
      [&](std::size_t done) {
        if (progress) progress(static_cast<int>(done), total);
      });
  return table;
}

BrdfSliceTable BrdfSliceTable::fromSlices(std::vector<double> thetaOut, std::vector<HaarMap> slices) {
  const std::size_t total = thetaOut.size();
  if (total < 1 || total > static_cast<std::size_t>(kMaxThetaSamples)) {
    throw std::invalid_argument("BrdfSliceTable::fromSlices: " + std::to_string(total) +
                                " thetaOut samples is outside [1, " + std::to_string(kMaxThetaSamples) + "]");
  }
  if (slices.size() != kChannels * total) {
    throw std::invalid_argument("BrdfSliceTable::fromSlices: " + std::to_string(slices.size()) + " slices for " +
                                std::to_string(kChannels) + " channels × " + std::to_string(total) + " thetaOut samples");
  }
  for (std::size_t t = 0; t < total; ++t) {
    // The same expression as build(), so a table that went through a file
    // compares equal bit for bit; the tolerance only forgives a writer that
    // computed the centres another way.
    const double expected = (static_cast<double>(t) + 0.5) * (kPi / 2.0) / static_cast<double>(total);
    if (!(std::abs(thetaOut[t] - expected) <= 1e-12)) {
      throw std::invalid_argument("BrdfSliceTable::fromSlices: thetaOut[" + std::to_string(t) + "] = " +
                                  std::to_string(thetaOut[t]) + " is not the cell centre " +
                                  std::to_string(expected));
    }
  }
  const int level = slices.front().level();
  checkLevel(level, "BrdfSliceTable::fromSlices");
  const std::size_t count = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  for (std::size_t i = 0; i < slices.size(); ++i) {
    if (slices[i].level() != level || slices[i].coefficientCount() != count) {
      throw std::invalid_argument("BrdfSliceTable::fromSlices: slice " + std::to_string(i) + " has level " +
                                  std::to_string(slices[i].level()) + ", slice 0 has level " + std::to_string(level));
    }
    for (const float c : slices[i].coefficients()) {
      if (!std::isfinite(c)) {
        throw std::invalid_argument("BrdfSliceTable::fromSlices: slice " + std::to_string(i) +
                                    " has a non-finite coefficient");
      }
    }
  }
  BrdfSliceTable table;
  table.level_ = level;
  table.thetaOut_ = std::move(thetaOut);
  table.slices_ = std::move(slices);
  return table;
}

}  // namespace haarcast
