// The token guard's server-wide limit and its bounded table, and the
// rate-limited refusal log, without sockets (the tests pass the clock).
#include "haarcast/net/token_guard.h"

#include <gtest/gtest.h>

#include "haarcast/net/refusal_log.h"

namespace haarcast::net {
namespace {

using namespace std::chrono_literals;

std::string address(int i) { return "10." + std::to_string(i / 65536) + "." + std::to_string(i / 256 % 256) + "." + std::to_string(i % 256); }

TEST(TokenGuard, ManyAddressesTripTheServerWideLimitButKnownClientsPass) {
  TokenGuard guard({/*maxFailures*/ 5, /*windowSeconds*/ 60, /*lockoutSeconds*/ 60, /*serverMaxFailures*/ 20});
  const auto t0 = Clock::now();
  guard.succeeded("192.0.2.7", t0);  // a client that has shown the right token
  // One guess each from 20 addresses: no address reaches its own limit.
  for (int i = 0; i < 19; ++i) {
    EXPECT_EQ(guard.check(address(i), t0), TokenGuard::Lock::None);
    guard.failed(address(i), t0 + 1ms * i);
  }
  EXPECT_EQ(guard.check("198.51.100.1", t0 + 20ms), TokenGuard::Lock::None);
  guard.failed(address(19), t0 + 20ms);
  EXPECT_EQ(guard.check("198.51.100.1", t0 + 21ms), TokenGuard::Lock::Server) << "a new address waits";
  EXPECT_EQ(guard.check(address(3), t0 + 21ms), TokenGuard::Lock::Server);
  EXPECT_EQ(guard.check("192.0.2.7", t0 + 21ms), TokenGuard::Lock::None) << "a known client goes on";
  EXPECT_EQ(guard.check("198.51.100.1", t0 + 61s), TokenGuard::Lock::None) << "the lock ends";
}

TEST(TokenGuard, AFullTableForgetsTheOldestUnlockedEntryNotTheLowestAddress) {
  TokenGuard guard({/*maxFailures*/ 2, 60, 60, /*serverMaxFailures*/ 1000000, /*maxAddresses*/ 8});
  const auto t0 = Clock::now();
  // 127.0.0.1 is locked; "0.0.0.1" sorts first and is seen first among the rest.
  guard.failed("127.0.0.1", t0);
  guard.failed("127.0.0.1", t0);
  ASSERT_EQ(guard.check("127.0.0.1", t0), TokenGuard::Lock::Address);
  guard.failed("0.0.0.1", t0 + 1ms);
  // A spray of fresh addresses, ten times the table.
  for (int i = 0; i < 80; ++i) guard.failed(address(i + 100), t0 + 2ms + 1ms * i);
  EXPECT_EQ(guard.addresses(), 8u);
  EXPECT_EQ(guard.check("127.0.0.1", t0 + 1s), TokenGuard::Lock::Address) << "the spray erased a lock";
  // The newest entries stay: one more failure locks the address.
  guard.failed(address(179), t0 + 1s);
  EXPECT_EQ(guard.check(address(179), t0 + 1s), TokenGuard::Lock::Address) << "a recent entry was forgotten";
}

TEST(TokenGuard, EntriesWhoseWindowIsOverGoFirst) {
  TokenGuard guard({2, /*windowSeconds*/ 10, /*lockoutSeconds*/ 10, 1000000, /*maxAddresses*/ 4});
  const auto t0 = Clock::now();
  for (int i = 0; i < 3; ++i) guard.failed(address(i), t0);
  guard.failed("c", t0 + 5s);
  guard.failed("c", t0 + 5s);  // locked until 15 s
  guard.failed("d", t0 + 20s);  // the three old windows are over: they go, "c" (lock over too) goes
  EXPECT_EQ(guard.addresses(), 1u);
}

TEST(RefusalLog, OneLinePerAddressPerPeriodAndASummary) {
  RefusalLog log(60.0, /*maxAddresses*/ 100);
  const auto t0 = Clock::now();
  int written = 0;
  // 1,000 refusals from 200 addresses in 0.2 s (a token spray).
  for (int i = 0; i < 1000; ++i) written += log.note(address(i % 200), t0 + 200us * i) ? 1 : 0;
  EXPECT_EQ(written, 100) << "one line per address, and at most the table's bound of addresses";
  EXPECT_FALSE(log.summary(t0 + 30s)) << "the period runs on";
  const auto line = log.summary(t0 + 61s);
  ASSERT_TRUE(line);
  EXPECT_EQ(*line, "1000 refusals from 100 addresses in the last 60 s; 900 not logged one by one");
  EXPECT_FALSE(log.summary(t0 + 200s)) << "said once";
  EXPECT_TRUE(log.note(address(0), t0 + 61s)) << "a new period: the address's line again";
  EXPECT_FALSE(log.summary(t0 + 130s)) << "nothing held back: no summary";
}

}  // namespace
}  // namespace haarcast::net
