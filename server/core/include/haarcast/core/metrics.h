// Error measures with one definition each (DESIGN.md "Measurements").
#pragma once

#include <span>

namespace haarcast {

struct ErrorStats {
  double mse = 0.0;
  double peak = 0.0;  // max of the reference
  double psnr = 0.0;  // 10·log10(peak²/MSE) dB; +inf when MSE is 0
  // sqrt(Σ(test − ref)² / Σ ref²) and Σ test / Σ ref (DESIGN.md
  // "Measurements"): what a small bright peak cannot hide. NaN when the
  // reference sums to zero.
  double relativeL2 = 0.0;
  double brightnessRatio = 0.0;
};

// PSNR of `test` against `reference` (same length, non-empty; throws
// std::invalid_argument otherwise). peak = max over the reference values.
ErrorStats compareSignals(std::span<const double> reference, std::span<const double> test);
ErrorStats compareSignals(std::span<const float> reference, std::span<const float> test);

}  // namespace haarcast
