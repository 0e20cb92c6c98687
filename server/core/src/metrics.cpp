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
  double squared = 0.0;
  for (std::size_t k = 0; k < reference.size(); ++k) {
    const double diff = static_cast<double>(test[k]) - static_cast<double>(reference[k]);
    squared += diff * diff;
  }
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
