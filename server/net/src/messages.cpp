#include "haarcast/net/messages.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace haarcast::net {

std::string welcomeMessage(const SessionConfig& config, const Catalog& catalog, const Limits& limits,
                           const WelcomeFacts& facts) {
  v1::ServerMessage m;
  auto* w = m.mutable_welcome();
  w->set_protocol_version(kProtocolVersion);
  w->set_session_id(facts.sessionId);
  w->set_server_version(kServerVersion);
  w->set_width(static_cast<std::uint32_t>(config.width));
  w->set_height(static_cast<std::uint32_t>(config.height));
  w->set_encoding(toWire(config.encoding));
  w->set_fps_cap(config.fps);
  for (const auto& s : catalog.scenes) w->add_scenes(s.name);
  for (const auto& mat : catalog.materials) w->add_materials(mat);
  for (const auto& probe : catalog.probes) w->add_probes(probe);
  for (const auto& mesh : catalog.meshes) w->add_meshes(mesh.name);
  *w->mutable_settings() = settingsToWire(config);
  w->set_object_count(static_cast<std::uint32_t>(facts.objectCount));
  w->set_device(facts.device);
  w->set_rays(facts.rays);
  *w->mutable_scene_info() = sceneInfo(config, catalog, facts.objectLevels);
  *w->mutable_limits() = limitsToWire(limits);
  return serialize(m);
}

std::string frameMessage(const SessionConfig& config, const render::Frame& frame, std::string encoded,
                         const FrameFacts& facts) {
  v1::ServerMessage m;
  auto* f = m.mutable_frame();
  f->set_sequence(facts.sequence);
  f->set_pose_sequence(facts.poseSequence);
  f->set_width(static_cast<std::uint32_t>(frame.width));
  f->set_height(static_cast<std::uint32_t>(frame.height));
  f->set_encoding(toWire(config.encoding));
  f->set_data(std::move(encoded));
  for (const auto& s : facts.stages) {
    auto* t = f->add_timings();
    t->set_name(s.name);
    t->set_ms(s.seconds * 1e3);
  }
  f->set_client_time_ms(facts.clientTimeMs);
  f->set_server_ms(facts.serverMs);
  *f->mutable_settings() = settingsToWire(config);
  f->set_exposure_stops(frame.exposureStops);
  if (frame.passSamples > 0) {
    f->set_directions_per_sample(static_cast<double>(frame.passDirections) / static_cast<double>(frame.passSamples));
    f->set_smooth_share(static_cast<double>(frame.smoothSamples) / static_cast<double>(frame.passSamples));
  }
  return serialize(m);
}

std::string statsMessage(const StatsFigures& figures) {
  v1::ServerMessage m;
  auto* s = m.mutable_stats();
  s->set_frames_sent(figures.framesSent);
  s->set_frames_dropped(figures.framesDropped);
  s->set_bytes_sent(figures.bytesSent);
  s->set_fps(figures.fps);
  s->set_render_ms_mean(figures.renderMsMean);
  s->set_sessions(figures.sessions);
  return serialize(m);
}

std::string errorLabel(v1::ErrorCode code) {
  std::string name = v1::ErrorCode_Name(code);
  constexpr std::string_view prefix = "ERROR_CODE_";
  if (name.rfind(prefix, 0) == 0) name = name.substr(prefix.size());
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return name.empty() ? std::to_string(static_cast<int>(code)) : name;
}

std::string sceneInfoMessage(const SessionConfig& config, const Catalog& catalog, const std::vector<int>& objectLevels) {
  v1::ServerMessage m;
  *m.mutable_scene_info() = sceneInfo(config, catalog, objectLevels);
  return serialize(m);
}

std::string pongMessage(std::uint64_t nonce) {
  v1::ServerMessage m;
  m.mutable_pong()->set_nonce(nonce);
  return serialize(m);
}

std::string errorMessage(const ProtocolError& e) {
  v1::ServerMessage m;
  auto* err = m.mutable_error();
  err->set_code(e.code);
  err->set_message(e.message);
  err->set_fatal(e.fatal);
  return serialize(m);
}

std::string buildProgressMessage(const BuildProgressUpdate& update) {
  v1::ServerMessage m;
  auto* b = m.mutable_build_progress();
  b->set_stage(publicStageName(update.stage));
  b->set_stage_index(static_cast<std::uint32_t>(update.stageIndex));
  b->set_done(update.done);
  b->set_total(update.total);
  b->set_fraction(update.fraction());
  b->set_elapsed_seconds(std::max(0.0, update.elapsedSeconds));
  b->set_estimated_stage_seconds_left(std::max(0.0, update.stageSecondsLeft));
  b->set_build_fraction(std::clamp(update.buildFraction, 0.0, 1.0));
  for (const std::string& stage : update.stages) b->add_stages(publicStageName(stage));
  b->set_estimated_build_seconds_left(std::max(0.0, update.buildSecondsLeft));
  return serialize(m);
}

std::string frameProgressMessage(const FrameProgressUpdate& update, int width, int height) {
  v1::ServerMessage m;
  auto* f = m.mutable_frame_progress();
  f->set_stage(update.stage);  // the backends' own names (renderer.h), never a client's
  f->set_stage_fraction(std::clamp(update.stageFraction, 0.0, 1.0));
  f->set_fraction(std::clamp(update.fraction, 0.0, 1.0));
  f->set_elapsed_seconds(std::max(0.0, update.elapsedSeconds));
  f->set_estimated_seconds_left(std::max(0.0, update.secondsLeft));
  f->set_width(static_cast<std::uint32_t>(std::max(0, width)));
  f->set_height(static_cast<std::uint32_t>(std::max(0, height)));
  return serialize(m);
}

std::string utf8Prefix(std::string_view text, std::size_t maxBytes) {
  if (text.size() <= maxBytes) return std::string(text);
  std::size_t end = maxBytes;
  // Back up over continuation bytes (10xxxxxx) to the lead byte of the
  // sequence the cut falls in; that sequence is dropped whole.
  while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
  return std::string(text.substr(0, end));
}

std::string sanitizeForLog(std::string_view text, std::size_t maxBytes) {
  const std::string kept = utf8Prefix(text, maxBytes);
  std::string out;
  out.reserve(kept.size() + 8);
  for (const char ch : kept) {
    const auto c = static_cast<unsigned char>(ch);
    switch (c) {
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      default:
        if (c < 0x20 || c == 0x7F) {
          char hex[8];
          std::snprintf(hex, sizeof hex, "\\x%02x", c);
          out += hex;
        } else {
          out += ch;
        }
    }
  }
  if (kept.size() < text.size()) out += "…";
  return out;
}

}  // namespace haarcast::net
