// Counts the heap allocations a thread makes, for tests that check that a
// warm per-pixel call allocates nothing. The counting operator new lives in
// allocation_counter.cpp and replaces the global one for the whole test
// binary; outside a counter's scope it only forwards to malloc.
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

}  // namespace haarcast::testing
