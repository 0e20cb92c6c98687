// The thread pool's loop (core/parallel.h): every index once, progress in
// order on the calling thread, the first failure rethrown, and without
// progress the calling thread working too.
#include "haarcast/core/parallel.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace haarcast {
namespace {

TEST(ParallelFor, EveryIndexRunsOnceWithAndWithoutProgress) {
  for (const unsigned threads : {1u, 2u, 8u}) {
    for (const std::size_t count : {std::size_t{1}, std::size_t{3}, std::size_t{1000}}) {
      for (const bool progress : {false, true}) {
        std::vector<std::atomic<int>> runs(count);
        std::vector<std::size_t> reported;
        const std::thread::id caller = std::this_thread::get_id();
        bool reportedElsewhere = false;
        const std::function<void(std::size_t)> onDone = [&](std::size_t done) {
          reported.push_back(done);
          reportedElsewhere |= std::this_thread::get_id() != caller;
        };
        parallelFor(count, [&](std::size_t i) { ++runs[i]; }, progress ? onDone : std::function<void(std::size_t)>{}, threads);
        for (std::size_t i = 0; i < count; ++i) ASSERT_EQ(runs[i].load(), 1) << i << ", " << threads << " threads";
        if (progress) {
          ASSERT_EQ(reported.size(), count);
          for (std::size_t k = 0; k < count; ++k) EXPECT_EQ(reported[k], k + 1);
          EXPECT_FALSE(reportedElsewhere);
        }
      }
    }
  }
}

// Without progress to report, one thread is the caller's: with one thread
// every item runs on it, with more it takes its share.
TEST(ParallelFor, WithoutProgressTheCallingThreadWorks) {
  const std::thread::id caller = std::this_thread::get_id();
  std::mutex mutex;
  std::set<std::thread::id> seen;
  parallelFor(50, [&](std::size_t) {
    const std::lock_guard lock(mutex);
    seen.insert(std::this_thread::get_id());
  }, {}, 1);
  EXPECT_EQ(seen, std::set<std::thread::id>{caller});
  // Two threads, items that wait until both have started one: the caller is one of them.
  seen.clear();
  std::atomic<int> started{0};
  const auto giveUp = std::chrono::steady_clock::now() + std::chrono::seconds(10);  // bounded: never hangs a CI
  parallelFor(2, [&](std::size_t) {
    ++started;
    while (started.load() < 2 && std::chrono::steady_clock::now() < giveUp) std::this_thread::yield();
    const std::lock_guard lock(mutex);
    seen.insert(std::this_thread::get_id());
  }, {}, 2);
  EXPECT_EQ(seen.size(), 2u);
  EXPECT_EQ(seen.count(caller), 1u);
}

TEST(ParallelFor, TheFirstFailureStopsTheLoopAndIsRethrown) {
  for (const bool progress : {false, true}) {
    std::atomic<std::size_t> ran{0};
    const auto body = [&](std::size_t i) {
      ++ran;
      if (i == 0) throw std::runtime_error("item 0");
    };
    try {
      parallelFor(100000, body, progress ? [](std::size_t) {} : std::function<void(std::size_t)>{}, 1);
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "item 0");
    }
    EXPECT_EQ(ran.load(), 1u) << "one thread: nothing handed out after the failure";
  }
}

}  // namespace
}  // namespace haarcast
