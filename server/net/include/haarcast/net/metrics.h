// Server-wide counters, exported at /metrics in the Prometheus text format
// (version 0.0.4). Counters are atomics so that sessions on any I/O thread
// and the render workers update them without a lock; the per-stage and
// per-error maps take a mutex (a few updates per frame).
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "haarcast/render/renderer.h"

namespace haarcast::net {

class Metrics {
 public:
  std::atomic<std::int64_t> sessions{0};           // gauge: WebSocket sessions open now
  std::atomic<std::uint64_t> sessionsTotal{0};     // accepted since start
  std::atomic<std::uint64_t> framesTotal{0};       // frames sent
  std::atomic<std::uint64_t> framesDropped{0};     // rendered, replaced before sending
  std::atomic<std::uint64_t> bytesTotal{0};        // frame payload bytes sent
  std::atomic<std::uint64_t> httpRequests{0};
  std::atomic<std::uint64_t> renderersBuilt{0};

  // One frame's stage times (seconds), "encode" included.
  void addStages(const std::vector<render::StageTime>& stages);
  // An Error sent (label: the ErrorCode's name without its prefix, "bad_message").
  void addError(const std::string& code);

  // The exposition: HELP and TYPE lines, then samples.
  std::string prometheusText() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::pair<double, std::uint64_t>> stages_;  // name → (sum seconds, count)
  std::map<std::string, std::uint64_t> errors_;
};

}  // namespace haarcast::net
