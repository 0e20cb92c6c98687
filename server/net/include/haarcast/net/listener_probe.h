// Whether a listener still accepts and an HTTP/2 server answers behind it:
// the gRPC port is probed end to end, through its front (grpc_front.h) to
// gRPC. The kernel completes TCP handshakes into the backlog of a port
// that no longer accepts (as gRPC 1.51's own listener did after EMFILE,
// CVE-2023-4785), so a connect alone proves nothing. The probe speaks first, as an HTTP/2 client does
// (RFC 9113 §3.4: the preface, then SETTINGS), and a live server answers
// with its own SETTINGS; a port that never accepts stays silent.
//
// ListenerWatch turns probes into a verdict: dead after a few silent ones
// in a row (a loaded server may be slow once), alive again at the first
// answer; a probe that could not even be made (no descriptor left: the
// exhaustion itself) says nothing either way.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace haarcast::net {

enum class ProbeResult {
  Answered,      // the server's SETTINGS frame came back
  Silent,        // connected (or refused) but no answer within the timeout
  Inconclusive,  // the probe could not be made here (socket(): EMFILE, ENFILE …)
};

// Connects to `host` (an IPv4 or IPv6 literal) on `port`, sends the
// HTTP/2 client preface and an empty SETTINGS frame, and waits up to
// `timeout` for a frame header of type SETTINGS. Never throws.
ProbeResult probeHttp2Listener(const std::string& host, std::uint16_t port, std::chrono::milliseconds timeout);

class ListenerWatch {
 public:
  explicit ListenerWatch(int silentToDie = 3) : silentToDie_(silentToDie) {}
  // One probe's result; true when it changed the verdict.
  bool record(ProbeResult result);
  bool dead() const { return dead_; }

 private:
  int silentToDie_;
  int silentInARow_ = 0;
  bool dead_ = false;
};

}  // namespace haarcast::net
