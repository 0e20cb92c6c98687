// The largest single heap request a thread makes within a scope, for tests
// that check that a loader refuses a hostile header before it allocates for
// it. The tracking operator new lives in allocation_peak.cpp and replaces the
// global one for the io test binary; outside a scope it only forwards to malloc.
#pragma once

#include <cstddef>

namespace haarcast::testing {

class AllocationPeak {
 public:
  AllocationPeak();
  ~AllocationPeak();
  AllocationPeak(const AllocationPeak&) = delete;
  AllocationPeak& operator=(const AllocationPeak&) = delete;
  // The largest operator new request on this thread since construction, in bytes.
  std::size_t largest() const;

 private:
  std::size_t saved_;
};

}  // namespace haarcast::testing
