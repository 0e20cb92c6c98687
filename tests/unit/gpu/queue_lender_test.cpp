// Which queue a Context submits to (queue_lender.h): the least-lent, lowest
// index among equals; a queue given back is the next one lent.
#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

#include "haarcast/gpu/queue_lender.h"

namespace haarcast::gpu {
namespace {

TEST(QueueLender, ContextsSpreadOverTheQueuesBeforeAnyIsShared) {
  QueueLender lender(4);
  std::vector<std::size_t> lent;
  for (int i = 0; i < 6; ++i) lent.push_back(lender.lend());
  // A renderer's four slots on four queues; the fifth and sixth Contexts share.
  EXPECT_EQ(lent, (std::vector<std::size_t>{0, 1, 2, 3, 0, 1}));
  EXPECT_EQ(lender.lent(), (std::vector<std::size_t>{2, 2, 1, 1}));
  // Queue 3's Context goes: its queue, now the least lent, is the next one lent.
  lender.giveBack(3);
  EXPECT_EQ(lender.lent(), (std::vector<std::size_t>{2, 2, 1, 0}));
  EXPECT_EQ(lender.lend(), 3u);
  EXPECT_EQ(lender.lend(), 2u);
  EXPECT_EQ(lender.lend(), 3u);
  EXPECT_EQ(lender.lent(), (std::vector<std::size_t>{2, 2, 2, 2}));
}

TEST(QueueLender, ADeviceOfOneQueueLendsItToEveryContext) {
  QueueLender lender(1);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(lender.lend(), 0u);
  EXPECT_EQ(lender.lent(), (std::vector<std::size_t>{5}));
  for (int i = 0; i < 5; ++i) lender.giveBack(0);
  EXPECT_EQ(lender.lent(), (std::vector<std::size_t>{0}));
}

}  // namespace
}  // namespace haarcast::gpu
