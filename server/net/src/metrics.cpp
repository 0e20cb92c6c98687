#include "haarcast/net/metrics.h"

#include <cstdio>
#include <sstream>

namespace haarcast::net {

void Metrics::addStages(const std::vector<render::StageTime>& stages) {
  std::lock_guard lock(mutex_);
  for (const auto& s : stages) {
    auto& [sum, count] = stages_[s.name];
    sum += s.seconds;
    ++count;
  }
}

void Metrics::addError(const std::string& code) {
  std::lock_guard lock(mutex_);
  ++errors_[code];
}

std::string Metrics::prometheusText() const {
  std::ostringstream out;
  auto metric = [&](const char* name, const char* type, const char* help) {
    out << "# HELP " << name << ' ' << help << "\n# TYPE " << name << ' ' << type << '\n';
  };
  metric("haarcast_sessions", "gauge", "WebSocket sessions open now.");
  out << "haarcast_sessions " << sessions.load() << '\n';
  metric("haarcast_sessions_total", "counter", "WebSocket sessions accepted since start.");
  out << "haarcast_sessions_total " << sessionsTotal.load() << '\n';
  metric("haarcast_frames_total", "counter", "Frames sent to clients.");
  out << "haarcast_frames_total " << framesTotal.load() << '\n';
  metric("haarcast_frames_dropped_total", "counter",
         "Frames rendered but replaced by a newer one before they could be sent (slow clients).");
  out << "haarcast_frames_dropped_total " << framesDropped.load() << '\n';
  metric("haarcast_bytes_total", "counter", "Encoded frame bytes sent to clients.");
  out << "haarcast_bytes_total " << bytesTotal.load() << '\n';
  metric("haarcast_http_requests_total", "counter", "Plain HTTP requests served.");
  out << "haarcast_http_requests_total " << httpRequests.load() << '\n';
  metric("haarcast_renderers_built_total", "counter", "Renderers prepared (scene, materials, level, method, backend).");
  out << "haarcast_renderers_built_total " << renderersBuilt.load() << '\n';

  std::lock_guard lock(mutex_);
  metric("haarcast_stage_seconds", "summary", "Time per frame stage, summed over frames.");
  for (const auto& [name, sc] : stages_) {
    char sum[64];
    std::snprintf(sum, sizeof sum, "%.9g", sc.first);
    out << "haarcast_stage_seconds_sum{stage=\"" << name << "\"} " << sum << '\n';
    out << "haarcast_stage_seconds_count{stage=\"" << name << "\"} " << sc.second << '\n';
  }
  metric("haarcast_errors_total", "counter", "Protocol errors sent to clients, by code.");
  for (const auto& [code, n] : errors_) out << "haarcast_errors_total{code=\"" << code << "\"} " << n << '\n';
  return out.str();
}

}  // namespace haarcast::net
