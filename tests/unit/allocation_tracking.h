// What a thread asks of the heap within a scope, for tests that check that
// a warm per-pixel call allocates nothing (AllocationCounter) or that a
// loader refuses a hostile header before it allocates for it
// (AllocationPeak). allocation_tracking.cpp replaces the global operator
// new of the test binary that compiles it; outside a scope it only forwards
// to malloc.
#pragma once

#include <cstddef>

namespace haarcast::testing {

class AllocationCounter {
 public:
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;
  // operator new calls on this thread since construction.
  std::size_t count() const;

 private:
  std::size_t start_;
};

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
