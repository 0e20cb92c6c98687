// The queue lender (queue_lender.h): the least-lent queue, lowest index first.
#include "haarcast/gpu/queue_lender.h"

#include <algorithm>

#include "haarcast/core/check.h"

namespace haarcast::gpu {

QueueLender::QueueLender(std::size_t queues) : queues_(queues), lent_(queues, 0) { HC_CHECK_LE(std::size_t{1}, queues); }

std::size_t QueueLender::lend() {
  std::lock_guard lock(mutex_);
  // min_element returns the first of equals: the lowest index.
  const auto least = std::min_element(lent_.begin(), lent_.end());
  ++*least;
  return static_cast<std::size_t>(least - lent_.begin());
}

void QueueLender::giveBack(std::size_t queue) {
  std::lock_guard lock(mutex_);
  HC_CHECK_LT(queue, queues_);
  HC_CHECK_LT(std::size_t{0}, lent_[queue]);
  --lent_[queue];
}

std::vector<std::size_t> QueueLender::lent() const {
  std::lock_guard lock(mutex_);
  return lent_;
}

}  // namespace haarcast::gpu
