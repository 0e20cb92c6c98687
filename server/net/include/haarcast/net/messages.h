// The ServerMessages a session emits (Welcome, Frame, Stats, SceneInfo,
// Pong, Error, BuildProgress), built from plain values, and the text that leaves the
// server for a peer or a log: a close reason cut on a UTF-8 boundary, a
// client-given string made safe for one log line. Pure functions, tested
// without sockets.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "haarcast/net/build_progress.h"
#include "haarcast/net/frame_progress.h"
#include "haarcast/net/protocol.h"
#include "haarcast/render/renderer.h"

namespace haarcast::net {

// RFC 6455 §5.5: a control frame's payload is ≤ 125 bytes, 2 of them the
// close code, so a close reason is ≤ 123 bytes.
inline constexpr std::size_t kMaxCloseReasonBytes = 123;
// A client-given string (client_name, a scene name) in a log line.
inline constexpr std::size_t kMaxLoggedClientBytes = 64;

// WebSocket close codes the server sends (RFC 6455 §7.4.1, 1013 from the
// IANA registry).
enum class CloseCode : std::uint16_t {
  Normal = 1000,
  GoingAway = 1001,       // shutting down
  PolicyError = 1008,     // a fatal protocol error
  TooBig = 1009,          // a message over the limit
  TryAgainLater = 1013,   // full: no session slot now
};

// What a Welcome says besides the config: the session's id and what its
// renderer reported.
struct WelcomeFacts {
  std::string sessionId;
  std::size_t objectCount = 0;
  std::string device;
  std::vector<int> objectLevels;  // render::Renderer::objectLevels (SceneInfo.Object.level)
  std::string rays;               // render::Renderer::rays: "device", "host" or "none"
};
std::string welcomeMessage(const SessionConfig& config, const Catalog& catalog, const Limits& limits,
                           const WelcomeFacts& facts);

// One rendered frame as the client sees it.
struct FrameFacts {
  std::uint64_t sequence = 0;
  std::uint64_t poseSequence = 0;
  double clientTimeMs = 0.0;
  double serverMs = 0.0;  // pose received → frame ready
  std::vector<render::StageTime> stages;
};
std::string frameMessage(const SessionConfig& config, const render::Frame& frame, std::string encoded,
                         const FrameFacts& facts);

// The Stats message's figures over one period.
struct StatsFigures {
  std::uint64_t framesSent = 0, framesDropped = 0, bytesSent = 0;
  double fps = 0.0;
  double renderMsMean = 0.0;
  std::uint32_t sessions = 0;
};
std::string statsMessage(const StatsFigures& figures);

// "ERROR_CODE_BAD_MESSAGE" → "bad_message": the /metrics label and log word.
std::string errorLabel(v1::ErrorCode code);

std::string sceneInfoMessage(const SessionConfig& config, const Catalog& catalog,
                             const std::vector<int>& objectLevels = {});
std::string pongMessage(std::uint64_t nonce);
std::string errorMessage(const ProtocolError& error);
// The stage goes out through publicStageName (build_progress.h).
std::string buildProgressMessage(const BuildProgressUpdate& update);
std::string frameProgressMessage(const FrameProgressUpdate& update, int width, int height);

// The longest prefix of `text` of at most `maxBytes` bytes that does not
// split a UTF-8 sequence (a truncated close reason must still be valid
// UTF-8, RFC 6455 §5.5.1).
std::string utf8Prefix(std::string_view text, std::size_t maxBytes);
inline std::string closeReason(std::string_view message) { return utf8Prefix(message, kMaxCloseReasonBytes); }

// A client-given string safe for one log line: control characters, '"' and
// '\' escaped (\n, \t, \x1b …), bounded to `maxBytes` of the input (cut on a
// UTF-8 boundary, "…" appended), so a name cannot forge or flood a line.
std::string sanitizeForLog(std::string_view text, std::size_t maxBytes = kMaxLoggedClientBytes);

}  // namespace haarcast::net
