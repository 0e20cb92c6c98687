// Comparisons shared by the core tests.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>

#include "haarcast/core/haar.h"
#include "haarcast/core/sphere_map.h"

namespace haarcast::testing {

inline double maxAbs(const HaarMap& a) {
  double m = 0.0;
  for (float v : a.coefficients()) m = std::max(m, static_cast<double>(std::abs(v)));
  return m;
}

inline double maxAbsDifference(const HaarMap& a, const HaarMap& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.coefficientCount(); ++i) m = std::max(m, static_cast<double>(std::abs(a[i] - b[i])));
  return m;
}

// Pixels uniform in [lo, hi).
inline SphereMap randomMap(int level, double lo, double hi, std::mt19937& rng) {
  std::uniform_real_distribution<double> dist(lo, hi);
  SphereMap map(level);
  for (float& x : map.values()) x = static_cast<float>(dist(rng));
  return map;
}

// Visibility-like: 0 or 1 per pixel, occluded with probability 0.4.
inline SphereMap randomBinaryMap(int level, std::mt19937& rng) {
  std::bernoulli_distribution visible(0.6);
  SphereMap map(level);
  for (float& x : map.values()) x = visible(rng) ? 1.0f : 0.0f;
  return map;
}

// Up to k random non-zero coefficients in [lo, hi), the scaling one always
// among them (positive, so the function has a positive mean).
inline SparseHaar randomSparse(int level, std::size_t k, double lo, double hi, std::mt19937& rng) {
  const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  std::uniform_real_distribution<double> value(lo, hi);
  HaarMap dense(level);
  dense[0] = static_cast<float>(std::abs(value(rng)) + 0.5);
  std::uniform_int_distribution<std::size_t> index(1, n - 1);
  for (std::size_t e = 1; e < std::min(k, n); ++e) dense[index(rng)] = static_cast<float>(value(rng));
  return SparseHaar::fromDense(dense);
}

}  // namespace haarcast::testing
