// The shared budgets: a pre-Hello budget that a few addresses cannot fill
// (a newcomer evicts the largest holder's oldest silent connection) and a
// session budget whose last slots are kept for new addresses, and the
// readiness that follows from both.
#include "haarcast/net/admission.h"

#include <vector>

#include <gtest/gtest.h>

namespace haarcast::net {
namespace {

std::string addr(int i) { return "127.0.0." + std::to_string(i + 2); }

TEST(Admission, EightAddressesCannotFillThePreHelloBudget) {
  Admission a({/*connectionsPerAddress*/ 32, /*pending*/ 64, /*pendingPerAddress*/ 8, /*sessions*/ 64,
               /*sessionsPerAddress*/ 16});
  std::vector<Admission::Slot> held;
  std::vector<int> evictedOf(8, 0);
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      auto s = a.take(SlotKind::Pending, addr(i));
      ASSERT_TRUE(s);
      ASSERT_TRUE(s->onEvicted([&evictedOf, i] { ++evictedOf[static_cast<std::size_t>(i)]; }));
      held.push_back(std::move(*s));
    }
  }
  ASSERT_EQ(a.count(SlotKind::Pending), 64);
  EXPECT_FALSE(a.fullForNewAddress()) << "a new address would be let in";
  // A ninth address: the oldest connection of a largest holder (the first
  // address's first) makes way.
  auto newcomer = a.take(SlotKind::Pending, "192.0.2.1");
  ASSERT_TRUE(newcomer);
  EXPECT_EQ(evictedOf, (std::vector<int>{1, 0, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(a.count(SlotKind::Pending), 64);
  EXPECT_EQ(a.count(SlotKind::Pending, addr(0)), 7);
  EXPECT_FALSE(held[0].onEvicted([] {})) << "the evicted slot knows it";
  held[0].release();  // its holder closes: not counted twice
  EXPECT_EQ(a.count(SlotKind::Pending), 64);
  EXPECT_EQ(a.count(SlotKind::Pending, addr(0)), 7);
  // The next one takes from a holder that still has 8, not from the first.
  ASSERT_TRUE(a.take(SlotKind::Pending, "192.0.2.2"));
  EXPECT_EQ(evictedOf, (std::vector<int>{1, 1, 0, 0, 0, 0, 0, 0}));
  EXPECT_EQ(a.evictions(), 2u);
  // A largest holder cannot evict its equals, and its own cap still holds.
  Admission::Refusal why;
  EXPECT_FALSE(a.take(SlotKind::Pending, addr(2), &why));
  EXPECT_EQ(why.label, "pending_per_address");
}

TEST(Admission, AnAddressEvictsOnlyFromOneHoldingMore) {
  Admission a({32, /*pending*/ 4, /*pendingPerAddress*/ 4, 64, 16});
  std::vector<Admission::Slot> held;
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) held.push_back(std::move(*a.take(SlotKind::Pending, addr(i))));
  }
  // Full, two holders of 2: one of them asking for a third is refused (it
  // would take from an equal), not let in at the other's expense.
  Admission::Refusal why;
  EXPECT_FALSE(a.take(SlotKind::Pending, addr(0), &why));
  EXPECT_EQ(why.label, "pending");
  EXPECT_FALSE(why.perAddress);
  EXPECT_EQ(a.count(SlotKind::Pending, addr(1)), 2);
  EXPECT_EQ(a.evictions(), 0u);
}

TEST(Admission, TheLastSessionSlotsAreKeptForNewAddresses) {
  Admission a({32, 64, 8, /*sessions*/ 64, /*sessionsPerAddress*/ 16});
  EXPECT_EQ(a.sessionReserve(), 8);
  std::vector<Admission::Slot> held;
  // Four addresses take what they can: 16 + 16 + 16 + 8.
  for (int i = 0; i < 4; ++i) {
    while (auto s = a.take(SlotKind::Session, addr(i))) held.push_back(std::move(*s));
  }
  EXPECT_EQ(a.count(SlotKind::Session), 56);
  EXPECT_EQ(a.count(SlotKind::Session, addr(3)), 8);
  Admission::Refusal why;
  EXPECT_FALSE(a.take(SlotKind::Session, addr(3), &why));
  EXPECT_EQ(why.label, "sessions_reserved");
  EXPECT_TRUE(why.perAddress);
  EXPECT_NE(why.reason.find("the last 8 of the server's 64 are kept for other addresses"), std::string::npos)
      << why.reason;
  EXPECT_FALSE(a.fullForNewAddress());
  // Eight new addresses get one each; then the budget is full for everyone.
  for (int i = 4; i < 12; ++i) {
    auto s = a.take(SlotKind::Session, addr(i));
    ASSERT_TRUE(s) << addr(i);
    held.push_back(std::move(*s));
  }
  EXPECT_TRUE(a.fullForNewAddress());
  EXPECT_FALSE(a.take(SlotKind::Session, "192.0.2.1", &why));
  EXPECT_EQ(why.label, "sessions");
}

TEST(Admission, NoGroupOfEightAddressesFillsTheSessionBudget) {
  Admission a({32, 64, 8, /*sessions*/ 64, /*sessionsPerAddress*/ 16});
  std::vector<Admission::Slot> held;
  // Round-robin greed, then each member tries again until none gets more.
  for (bool more = true; more;) {
    more = false;
    for (int i = 0; i < 8; ++i) {
      if (auto s = a.take(SlotKind::Session, addr(i))) {
        held.push_back(std::move(*s));
        more = true;
      }
    }
  }
  EXPECT_LT(a.count(SlotKind::Session), 64);
  EXPECT_FALSE(a.fullForNewAddress());
  EXPECT_TRUE(a.take(SlotKind::Session, "192.0.2.1"));
}

TEST(Admission, AReserveOfZeroAndSmallBudgets) {
  Admission none({32, 64, 8, /*sessions*/ 4, /*sessionsPerAddress*/ 4, /*sessionReserve*/ 0});
  std::vector<Admission::Slot> held;
  for (int i = 0; i < 4; ++i) held.push_back(std::move(*none.take(SlotKind::Session, "proxy")));
  EXPECT_TRUE(none.fullForNewAddress());
  EXPECT_EQ(Admission({32, 64, 8, /*sessions*/ 16, 16}).sessionReserve(), 4);
  EXPECT_EQ(Admission({32, 64, 8, /*sessions*/ 1, 1, /*sessionReserve*/ 5}).sessionReserve(), 0);
}

}  // namespace
}  // namespace haarcast::net
