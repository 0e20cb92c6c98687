// Which of a device's queues a Context submits to (engine.h).
//
// Why several queues: a pipeline barrier orders the commands before it in
// its own queue's submission order, whichever command buffer or renderer
// recorded them. On one queue every barrier of one frame therefore waits for
// the work of every frame submitted before it, and frames of different
// sessions take turns pass by pass even when each has its own command
// buffers. Frames on different queues order nothing across each other, so
// the device runs them side by side (where one frame's pass leaves the
// device idle between barriers, or does not fill it, another's fills it).
//
// The rule: a new Context takes the queue lent to the fewest Contexts now
// (the lowest index among equals), so a renderer's frame slots, made one
// after another, land on different queues while there are queues to spare,
// and a queue given back is the next one lent. Thread-safe.
#pragma once

#include <cstddef>
#include <mutex>
#include <vector>

namespace haarcast::gpu {

class QueueLender {
 public:
  // `queues` ≥ 1: the queues the device was opened with.
  explicit QueueLender(std::size_t queues);

  std::size_t queues() const { return queues_; }
  // The index of the queue to submit to, lent until giveBack().
  std::size_t lend();
  void giveBack(std::size_t queue);
  // Contexts each queue is lent to now.
  std::vector<std::size_t> lent() const;

 private:
  const std::size_t queues_;
  mutable std::mutex mutex_;
  std::vector<std::size_t> lent_;
};

}  // namespace haarcast::gpu
