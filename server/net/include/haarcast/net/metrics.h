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
#include <string_view>
#include <vector>

#include "haarcast/render/renderer.h"

namespace haarcast::net {

class Metrics {
 public:
  std::atomic<std::int64_t> sessions{0};           // gauge: sessions open now (after a valid Hello), both transports
  std::atomic<std::int64_t> pending{0};            // gauge: WebSocket connections waiting for their Hello
  std::atomic<std::int64_t> sessionCapacity{0};    // gauge: --max-sessions
  std::atomic<bool> draining{false};               // stop() called: /readyz answers 503
  std::atomic<std::uint64_t> sessionsTotal{0};     // accepted since start
  std::atomic<std::uint64_t> framesTotal{0};       // frames sent
  std::atomic<std::uint64_t> framesDropped{0};     // rendered, replaced before sending
  std::atomic<std::uint64_t> bytesTotal{0};        // frame payload bytes sent
  // The gRPC transport's share of sessions, sessionsTotal, framesTotal and
  // bytesTotal (which count both transports).
  std::atomic<std::int64_t> grpcSessions{0};
  std::atomic<std::uint64_t> grpcSessionsTotal{0};
  std::atomic<std::uint64_t> grpcFramesTotal{0};
  std::atomic<std::uint64_t> grpcBytesTotal{0};
  std::atomic<std::uint64_t> httpRequests{0};
  std::atomic<std::uint64_t> renderersBuilt{0};
  // Of them, by where their shadow rays are traced (render::Renderer::rays):
  // on the device, on the host, none (the rotating methods).
  std::atomic<std::uint64_t> renderersRaysDevice{0}, renderersRaysHost{0}, renderersRaysNone{0};
  std::atomic<std::uint64_t> renderFailures{0};    // frames that failed to render (each one, said or folded)
  std::atomic<std::uint64_t> framesCancelled{0};   // frame jobs ended without a frame (session gone, request replaced, stop)
  std::atomic<std::uint64_t> framesAbandoned{0};   // frames past the frame deadline (render_service.h)
  // Gauges of the render service, copied in just before each exposition
  // (Server: the service owns the numbers).
  std::atomic<std::uint64_t> pixelsInFlight{0};    // width × height of the frames rendering now
  std::atomic<std::uint64_t> pixelBudget{0};       // --server-pixel-budget (0 = none)
  std::atomic<std::uint64_t> queuedBuilds{0};      // renderer builds waiting
  std::atomic<std::uint64_t> maxQueuedBuilds{0};   // --max-queued-builds
  std::atomic<std::uint64_t> renderThreadsStuck{0};  // render threads left behind, not returned
  std::atomic<double> frameDeadlineSeconds{0.0};   // --frame-deadline (0 = none)
  // Each device rendered on and whether it is healthy (render_service.h
  // DeviceStatus), copied in like the gauges above.
  struct DeviceHealth {
    std::string backend;
    std::string device;
    bool healthy = true;
  };
  void setDevices(std::vector<DeviceHealth> devices);

  // One frame's stage times (seconds), "encode" included.
  void addStages(const std::vector<render::StageTime>& stages);
  // An Error sent (label: the ErrorCode's name without its prefix, "bad_message").
  void addError(const std::string& code);
  // One per event, by label (the labels are fixed words of the server's,
  // never client text, so the series stay few):
  void addHttpResponse(int status);               // every HTTP response, by status ("404")
  void addTimeout(std::string_view phase);        // "http_request", "hello", "idle", "write", "close"
  void addCut(std::string_view reason);           // a session the server ended, by why
  void addWebSocketViolation(std::string_view kind);  // a frame Beast refused ("message_too_big", "protocol")
  void addRefusal(std::string_view reason);       // a connection or upgrade turned away ("origin", "token_rate" …)

  // The exposition: HELP and TYPE lines, then samples.
  std::string prometheusText() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::pair<double, std::uint64_t>> stages_;  // name → (sum seconds, count)
  std::map<std::string, std::uint64_t> errors_;
  std::vector<DeviceHealth> devices_;
  // family name → label value → count
  std::map<std::string, std::map<std::string, std::uint64_t>, std::less<>> labelled_;
  void addLabelled(std::string_view family, std::string_view label);
};

}  // namespace haarcast::net
