// One client session over Beast's WebSocket: connect, upgrade (token in the
// Authorization header), Hello → (BuildProgress …) → Welcome, then play the
// pose path and count the frames that answer it. Several sessions share one io_context for
// `--clients N`; each reads and writes on its own, one write in flight.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include <boost/asio/io_context.hpp>

#include "haarcast/client/client_options.h"
#include "haarcast/proto/haarcast.pb.h"
#include "haarcast/client/pose_path.h"
#include "haarcast/client/run_stats.h"

namespace haarcast::client {

struct SessionConfig {
  WsUrl url;
  std::string token;  // sent as "Authorization: Bearer T" and in Hello
  v1::Hello hello;    // everything but the token
  const PosePath* path = nullptr;
  std::uint64_t frames = 0;   // poses to play
  std::uint64_t inFlight = 1; // poses sent ahead of their frames (1 = closed loop)
  std::uint64_t warmup = 0;   // poses played first and left out of every figure
  double durationSeconds = 0; // > 0: stop sending poses after this long (the path cycles)
  std::string outDir;         // empty: do not record
  bool checkNotBlank = false;
  // Fail a frame with more than this share of its pixels at 255 in a
  // channel (blown out); < 0: not checked.
  double maxClipped = -1.0;
  double timeoutSeconds = 30.0;  // for the upgrade, Welcome, and each frame
  std::chrono::steady_clock::time_point runStart;
};

// What the progress display needs from each answered frame.
struct FrameEvent {
  std::size_t client = 0;
  std::uint64_t pose = 0;  // the pose sequence the frame answers
  double latencyMs = 0.0;
  std::size_t bytes = 0;
};

class Session {
 public:
  using FrameCallback = std::function<void(const FrameEvent&)>;
  using MessageCallback = std::function<void(const std::string&)>;  // a line for stderr
  // The server builds this session's renderer: a BuildProgress (client
  // index, the message), then nullptr once the renderer is ready (Welcome).
  using BuildCallback = std::function<void(std::size_t client, const v1::BuildProgress* progress)>;

  Session(boost::asio::io_context& io, std::size_t index, SessionConfig config, SessionStats& stats,
          FrameCallback onFrame, MessageCallback onMessage, BuildCallback onBuild = {});
  // Connects, upgrades and sends the Hello. `answered`, if given, is called
  // once: when the server first answers (any message) or the session fails,
  // i.e. when the connection no longer holds one of the server's pre-Hello
  // slots (--max-pending-per-address).
  void start(std::function<void()> answered = {});
  // The Welcome as received (empty before it arrives).
  const v1::Welcome& welcome() const;

 private:
  // The state lives in a shared Impl that every pending handler keeps
  // alive, so a Session handle may be dropped while its I/O finishes.
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace haarcast::client
