// Comparisons shared by the core tests.
#pragma once

#include <algorithm>
#include <cmath>

#include "haarcast/core/haar.h"

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

}  // namespace haarcast::testing
