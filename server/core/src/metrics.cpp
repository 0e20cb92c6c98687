#include "haarcast/core/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace haarcast {
namespace {

template <typename T>
ErrorStats compare(std::span<const T> reference, std::span<const T> test) {
  if (reference.empty()) throw std::invalid_argument("compareSignals: empty reference");
  if (reference.size() != test.size()) {
    throw std::invalid_argument("compareSignals: reference has " + std::to_string(reference.size()) +
                                " values but test has " + std::to_string(test.size()));
  }
  ErrorStats stats;
  double squared = 0.0, referenceSquared = 0.0, referenceSum = 0.0, testSum = 0.0;
  for (std::size_t k = 0; k < reference.size(); ++k) {
    const double r = static_cast<double>(reference[k]), t = static_cast<double>(test[k]);
    squared += (t - r) * (t - r);
    referenceSquared += r * r;
    referenceSum += r;
    testSum += t;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  stats.relativeL2 = referenceSquared > 0.0 ? std::sqrt(squared / referenceSquared) : nan;
  stats.brightnessRatio = referenceSum != 0.0 ? testSum / referenceSum : nan;
  stats.mse = squared / static_cast<double>(reference.size());
  stats.peak = static_cast<double>(*std::max_element(reference.begin(), reference.end()));
  // DESIGN.md "Measurements": PSNR = 10·log10(peak² / MSE).
  stats.psnr = stats.mse == 0.0 ? std::numeric_limits<double>::infinity()
                                : 10.0 * std::log10(stats.peak * stats.peak / stats.mse);
  return stats;
}

}  // namespace

ErrorStats compareSignals(std::span<const double> reference, std::span<const double> test) {
  return compare(reference, test);
}

ErrorStats compareSignals(std::span<const float> reference, std::span<const float> test) {
  return compare(reference, test);
}

}  // namespace haarcast
