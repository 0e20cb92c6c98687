#include "allocation_tracking.h"

#include <algorithm>
#include <cstdlib>
#include <new>

namespace {
thread_local std::size_t allocations = 0;
thread_local std::size_t largestRequest = 0;

void* allocate(std::size_t size) {
  ++allocations;
  largestRequest = std::max(largestRequest, size);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t size) { return allocate(size); }
void* operator new[](std::size_t size) { return allocate(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace haarcast::testing {

AllocationCounter::AllocationCounter() : start_(allocations) {}
AllocationCounter::~AllocationCounter() = default;
std::size_t AllocationCounter::count() const { return allocations - start_; }

// Scopes nest: each starts from zero and hands the outer scope its peak back.
AllocationPeak::AllocationPeak() : saved_(largestRequest) { largestRequest = 0; }
AllocationPeak::~AllocationPeak() { largestRequest = std::max(saved_, largestRequest); }
std::size_t AllocationPeak::largest() const { return largestRequest; }

}  // namespace haarcast::testing
