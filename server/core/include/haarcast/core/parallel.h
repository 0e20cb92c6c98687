// The one thread pool of haarcast: every parallel loop (slice tables,
// rotation matrices, visibility, both renderers) runs through it.
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace haarcast {

// Runs body(i) for i = 0 … count−1 on up to `threads` threads (0 = the
// hardware's concurrency; at least 1), which take indices from a shared
// counter. If onDone is given, the calling thread waits and calls
// onDone(done) for done = 1, 2, … as items complete — in order, on the
// calling thread, so it needs no locking. Without it the calling thread is
// one of the `threads` and nobody is woken per item: a frame's loops run
// thousands of rows, and a wake-up for each cost a context switch each.
//
// The first exception, from body or from onDone, stops the handing out of new
// indices (items already running finish); the workers are joined and that
// exception is rethrown on the calling thread. After a failure in body, items
// that completed may go unreported.
inline void parallelFor(std::size_t count, const std::function<void(std::size_t)>& body,
                        const std::function<void(std::size_t done)>& onDone = {}, unsigned threads = 0) {
  if (count == 0) return;
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::condition_variable cv;
  std::size_t done = 0;        // guarded by mutex
  std::exception_ptr failure;  // guarded by mutex

  const bool reporting = static_cast<bool>(onDone);
  auto worker = [&] {
    for (std::size_t i = next.fetch_add(1); i < count && !stop.load(); i = next.fetch_add(1)) {
      try {
        body(i);
        if (reporting) {
          const std::lock_guard lock(mutex);
          ++done;
        }
      } catch (...) {
        const std::lock_guard lock(mutex);
        if (!failure) failure = std::current_exception();
        stop = true;
      }
      if (reporting) cv.notify_one();
    }
  };

  const std::size_t wanted = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  const std::size_t threadCount = std::min(count, wanted);
  std::vector<std::jthread> pool;
  if (!reporting) {
    // The calling thread works too; the others are joined before returning.
    pool.reserve(threadCount - 1);
    try {
      for (std::size_t k = 1; k < threadCount; ++k) pool.emplace_back(worker);
    } catch (...) {
      stop = true;
      pool.clear();  // joins
      throw;
    }
    worker();
    pool.clear();  // joins
    if (failure) std::rethrow_exception(failure);
    return;
  }
  pool.reserve(threadCount);
  try {
    for (std::size_t k = 0; k < threadCount; ++k) pool.emplace_back(worker);
    std::size_t reported = 0;
    while (reported < count) {
      std::size_t now = 0;
      {
        std::unique_lock lock(mutex);
        cv.wait(lock, [&] { return done > reported || failure; });
        if (failure) break;
        now = done;
      }
      // Report each completed item, outside the lock.
      while (reported < now) {
        ++reported;
        if (onDone) onDone(reported);
      }
    }
  } catch (...) {
    stop = true;
    pool.clear();  // joins
    throw;
  }
  pool.clear();  // joins
  if (failure) std::rethrow_exception(failure);
}

}  // namespace haarcast
