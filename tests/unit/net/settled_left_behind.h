// The process's count of threads left behind (net/left_behind.h) once it
// holds still: tests in one process release their stuck renders as they
// end, and those threads may still be returning when the next test starts.
#pragma once

#include <chrono>
#include <cstddef>
#include <thread>

#include "haarcast/net/left_behind.h"

namespace haarcast::net {

inline std::size_t settledThreadsLeftBehind() {
  std::size_t count = threadsLeftBehind();
  for (int i = 0; i < 50; ++i) {  // at most 10 s
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    const std::size_t now = threadsLeftBehind();
    if (now == count) break;
    count = now;
  }
  return count;
}

}  // namespace haarcast::net
