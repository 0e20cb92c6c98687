// What `haarcast-client` was asked to do, parsed and checked, independent of
// sockets, so that the parsing rules are tested without a server.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "haarcast/proto/haarcast.pb.h"

namespace haarcast::client {

// ws://HOST:PORT[/PATH][?QUERY]. The path defaults to /ws, the server's
// WebSocket endpoint, so `haarcast-client ws://127.0.0.1:8080` just works.
struct WsUrl {
  std::string host;
  std::string port;
  std::string target;  // path and query, e.g. "/ws?token=abc"
};

// Throws std::invalid_argument naming the URL and what is wrong with it
// (wss:// is refused by name: TLS belongs to a proxy in front of the server).
WsUrl parseWsUrl(const std::string& url);

// The same URL with "token=T" added to its query (percent-encoded), for
// servers behind proxies that drop the Authorization header.
std::string withTokenQuery(const std::string& target, const std::string& token);

// "256x256" → {256, 256}; throws std::invalid_argument on anything else,
// including a zero side. The largest side is the server's to say
// (Welcome.limits.max_width, max_height; its refusal names the range).
struct Size {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
};
Size parseSize(const std::string& text);

// "jpeg" | "png" | "raw" | "exr" | "h264", the names wire::encodingName gives
// (and "jpg", "rgba8" for raw, "h.264").
v1::Encoding parseEncoding(const std::string& name);
// The extension of a frame written under --out. H.264 frames are written as
// PNG: one access unit depends on the ones before it and is no file of its own.
std::string encodingFileExtension(v1::Encoding encoding);

// --bitrate and --keyframe-interval (0 = the server's default), checked
// against what they apply to: H.264 only, and H.264 (4:2:0) wants an even
// width and height (proto/haarcast.proto, ENCODING_H264). Throws
// std::invalid_argument naming the flag and the valid choices.
struct H264Options {
  std::uint32_t bitrateKbps = 0;
  std::uint32_t keyframeInterval = 0;
};
void checkH264Options(v1::Encoding encoding, const Size& size, const H264Options& options);

// "auto" → automatic exposure; a number → that many stops, fixed.
struct Exposure {
  v1::ExposureMode mode = v1::EXPOSURE_MODE_AUTO;
  double stops = 0.0;
};
Exposure parseExposure(const std::string& text);

// --level: "" or "0" → the server's default; "N" → every object at level N
// (LEVEL_MODE_FIXED); "auto" → each object at the level its material
// needs, up to the cap in effect; "auto:N" → the same with cap N
// (LEVEL_MODE_AUTO). N ≥ 1 here; the server checks it against its own
// range (Welcome.limits) and names that range when it refuses one.
struct LevelRequest {
  std::uint32_t level = 0;  // 0: unchanged
  v1::LevelMode mode = v1::LEVEL_MODE_UNSPECIFIED;
};
LevelRequest parseLevel(const std::string& text);

// "fused" | "haar" | "spatial" | "matrix" | "table"; "" = server default.
v1::RotationMethod parseMethod(const std::string& name);
// --tone reinhard | aces | agx ("" → unspecified: the server's, Reinhard).
v1::ToneCurve parseToneCurve(const std::string& name);
std::string methodName(v1::RotationMethod method);

}  // namespace haarcast::client
