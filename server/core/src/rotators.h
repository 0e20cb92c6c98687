// Private: one factory per rotation method, called by makeRotator().
#pragma once

#include <memory>
#include <vector>

#include "haarcast/core/rotation.h"

namespace haarcast::detail {

void checkSlices(const std::vector<HaarMap>& slices, const char* who);

std::unique_ptr<SliceRotator> makeHaarRotator(std::vector<HaarMap> slices, const RotatorOptions& options);
std::unique_ptr<SliceRotator> makeSpatialRotator(std::vector<HaarMap> slices, const RotatorOptions& options);
std::unique_ptr<SliceRotator> makeMatrixRotator(std::vector<HaarMap> slices, const RotatorOptions& options);
std::unique_ptr<SliceRotator> makeTableRotator(std::vector<HaarMap> slices, const RotatorOptions& options);

inline std::size_t coefficientBytes(const std::vector<HaarMap>& maps) {
  std::size_t bytes = 0;
  for (const auto& m : maps) bytes += m.coefficientCount() * sizeof(float);
  return bytes;
}

}  // namespace haarcast::detail
