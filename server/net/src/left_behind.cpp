// The count of threads left behind (left_behind.h).
#include "haarcast/net/left_behind.h"

#include <atomic>
#include <cstdio>
#include <cstdlib>

#include "haarcast/core/check.h"

namespace haarcast::net {
namespace {

// Constant-initialised: valid before and after every other static.
std::atomic<std::size_t> gLeft{0};

}  // namespace

void noteThreadLeftBehind() { gLeft.fetch_add(1); }

void noteLeftThreadReturned() {
  const std::size_t before = gLeft.fetch_sub(1);
  HC_CHECK_LT(std::size_t{0}, before);
}

std::size_t threadsLeftBehind() { return gLeft.load(); }

void exitNowIfThreadsLeftBehind(int status) {
  if (gLeft.load() == 0) return;
  std::fflush(stdout);
  std::fflush(stderr);
  std::_Exit(status);
}

}  // namespace haarcast::net
