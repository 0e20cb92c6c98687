#include "haarcast/net/metrics.h"

#include "haarcast/io/cache_rebuilds.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace haarcast::net {
namespace {

// The labelled counter families: name, label key, help.
struct Family {
  const char* name;
  const char* label;
  const char* help;
};
constexpr Family kHttpResponses{"haarcast_http_responses_total", "status", "HTTP responses sent, by status."};
constexpr Family kTimeouts{"haarcast_timeouts_total", "phase",
                           "Connections ended for a timeout, by phase (http_request, hello, idle, write, close)."};
constexpr Family kCuts{"haarcast_session_cuts_total", "reason",
                       "WebSocket connections the server ended, by reason (the fatal Error's code, or the transport's)."};
constexpr Family kViolations{"haarcast_websocket_violations_total", "kind",
                             "WebSocket protocol violations by clients (frames Beast refused)."};
constexpr Family kRefusals{"haarcast_refusals_total", "reason",
                           "Connections and upgrades turned away (origin, token, per-address and server budgets)."};
constexpr Family kFamilies[] = {kHttpResponses, kTimeouts, kCuts, kViolations, kRefusals};

// The process figures every Prometheus client library exports under these
// names (so dashboards and `haarcast loadtest --url` read them unchanged):
// CPU seconds from getrusage, resident bytes from /proc/self/statm.
double processCpuSeconds() {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return -1.0;
  auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
  return seconds(u.ru_utime) + seconds(u.ru_stime);
}

long long processResidentBytes() {
  std::ifstream statm("/proc/self/statm");
  long long sizePages = 0, residentPages = 0;
  if (!(statm >> sizePages >> residentPages)) return -1;
  return residentPages * static_cast<long long>(sysconf(_SC_PAGESIZE));
}

// A label value as the text format wants it: backslash, double quote and
// newline escaped (device names come from drivers).
std::string labelValue(std::string_view value) {
  std::string out;
  for (const char c : value) {
    if (c == '\\' || c == '"') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

void Metrics::setDevices(std::vector<DeviceHealth> devices) {
  std::lock_guard lock(mutex_);
  devices_ = std::move(devices);
}

void Metrics::addLabelled(std::string_view family, std::string_view label) {
  std::lock_guard lock(mutex_);
  auto it = labelled_.find(family);
  if (it == labelled_.end()) it = labelled_.emplace(std::string(family), std::map<std::string, std::uint64_t>{}).first;
  ++it->second[std::string(label)];
}

void Metrics::addHttpResponse(int status) { addLabelled(kHttpResponses.name, std::to_string(status)); }
void Metrics::addTimeout(std::string_view phase) { addLabelled(kTimeouts.name, phase); }
void Metrics::addCut(std::string_view reason) { addLabelled(kCuts.name, reason); }
void Metrics::addWebSocketViolation(std::string_view kind) { addLabelled(kViolations.name, kind); }
void Metrics::addRefusal(std::string_view reason) { addLabelled(kRefusals.name, reason); }

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
  if (const double cpu = processCpuSeconds(); cpu >= 0.0) {
    metric("process_cpu_seconds_total", "counter", "User and system CPU time of the server process, in seconds.");
    out << "process_cpu_seconds_total " << cpu << '\n';
  }
  if (const long long rss = processResidentBytes(); rss >= 0) {
    metric("process_resident_memory_bytes", "gauge", "Resident memory of the server process, in bytes.");
    out << "process_resident_memory_bytes " << rss << '\n';
  }
  metric("haarcast_sessions", "gauge", "Sessions open now, WebSocket and gRPC (counted from a valid Hello).");
  out << "haarcast_sessions " << sessions.load() << '\n';
  metric("haarcast_pending_connections", "gauge", "WebSocket connections waiting for their Hello.");
  out << "haarcast_pending_connections " << pending.load() << '\n';
  // Capacity and budget in use, one series per budget, so that a pixel
  // budget joins as budget="pixels".
  metric("haarcast_capacity", "gauge", "What each budget allows (sessions: --max-sessions).");
  out << "haarcast_capacity{budget=\"sessions\"} " << sessionCapacity.load() << '\n';
  out << "haarcast_capacity{budget=\"pixels\"} " << pixelBudget.load() << '\n';
  out << "haarcast_capacity{budget=\"builds\"} " << maxQueuedBuilds.load() << '\n';
  metric("haarcast_budget_in_use", "gauge", "How much of each budget is taken now.");
  out << "haarcast_budget_in_use{budget=\"sessions\"} " << sessions.load() << '\n';
  out << "haarcast_budget_in_use{budget=\"pixels\"} " << pixelsInFlight.load() << '\n';
  out << "haarcast_budget_in_use{budget=\"builds\"} " << queuedBuilds.load() << '\n';
  metric("haarcast_pixels_in_flight", "gauge", "Width × height of the frames rendering now.");
  out << "haarcast_pixels_in_flight " << pixelsInFlight.load() << '\n';
  metric("haarcast_pixel_budget", "gauge", "Pixels that may render at once across the server (0 = no budget).");
  out << "haarcast_pixel_budget " << pixelBudget.load() << '\n';
  metric("haarcast_queued_builds", "gauge", "Renderer builds waiting for the builder thread.");
  out << "haarcast_queued_builds " << queuedBuilds.load() << '\n';
  metric("haarcast_draining", "gauge", "1 while the server drains for shutdown.");
  out << "haarcast_draining " << (draining.load() ? 1 : 0) << '\n';
  metric("haarcast_sessions_total", "counter", "Sessions accepted since start, WebSocket and gRPC.");
  out << "haarcast_sessions_total " << sessionsTotal.load() << '\n';
  metric("haarcast_frames_total", "counter", "Frames sent to clients.");
  out << "haarcast_frames_total " << framesTotal.load() << '\n';
  metric("haarcast_frames_dropped_total", "counter",
         "Frames rendered but replaced by a newer one before they could be sent (slow clients).");
  out << "haarcast_frames_dropped_total " << framesDropped.load() << '\n';
  metric("haarcast_bytes_total", "counter", "Encoded frame bytes sent to clients.");
  out << "haarcast_bytes_total " << bytesTotal.load() << '\n';
  // The gRPC share of the four above (transport="grpc"); the WebSocket
  // share is the difference.
  metric("haarcast_transport_sessions", "gauge", "Sessions open now, by transport.");
  out << "haarcast_transport_sessions{transport=\"grpc\"} " << grpcSessions.load() << '\n';
  metric("haarcast_transport_sessions_total", "counter", "Sessions accepted since start, by transport.");
  out << "haarcast_transport_sessions_total{transport=\"grpc\"} " << grpcSessionsTotal.load() << '\n';
  metric("haarcast_transport_frames_total", "counter", "Frames sent, by transport.");
  out << "haarcast_transport_frames_total{transport=\"grpc\"} " << grpcFramesTotal.load() << '\n';
  metric("haarcast_transport_bytes_total", "counter", "Encoded frame bytes sent, by transport.");
  out << "haarcast_transport_bytes_total{transport=\"grpc\"} " << grpcBytesTotal.load() << '\n';
  metric("haarcast_http_requests_total", "counter", "Plain HTTP requests served.");
  out << "haarcast_http_requests_total " << httpRequests.load() << '\n';
  metric("haarcast_renderers_built_total", "counter", "Renderers prepared (scene, materials, level, method, backend).");
  out << "haarcast_renderers_built_total " << renderersBuilt.load() << '\n';
  metric("haarcast_renderers_rays_total", "counter",
         "Renderers prepared, by where their shadow rays are traced: on the device (the GPU), the host (Embree), none.");
  out << "haarcast_renderers_rays_total{rays=\"device\"} " << renderersRaysDevice.load() << '\n';
  out << "haarcast_renderers_rays_total{rays=\"host\"} " << renderersRaysHost.load() << '\n';
  out << "haarcast_renderers_rays_total{rays=\"none\"} " << renderersRaysNone.load() << '\n';
  metric("haarcast_render_failures_total", "counter",
         "Frames that failed to render; each is told to its client (the same message again at most once a second, "
         "with a count).");
  out << "haarcast_render_failures_total " << renderFailures.load() << '\n';
  metric("haarcast_cache_rebuilds_total", "counter",
         "Cache files (slice tables, visibility) that were there but unusable, so their result was computed again: "
         "corrupt, stale (another version or options) or unreadable.");
  for (const io::CacheRebuildReason reason : io::kCacheRebuildReasons) {
    out << "haarcast_cache_rebuilds_total{reason=\"" << io::cacheRebuildReasonName(reason) << "\"} "
        << io::cacheRebuilds(reason) << '\n';
  }
  metric("haarcast_frames_cancelled_total", "counter",
         "Frame jobs ended without a frame: the session had gone, its request was replaced, or the server stopped.");
  out << "haarcast_frames_cancelled_total " << framesCancelled.load() << '\n';
  metric("haarcast_frames_abandoned_total", "counter",
         "Frames abandoned at the frame deadline: their session got an error naming the stage, their device turned "
         "unhealthy.");
  out << "haarcast_frames_abandoned_total " << framesAbandoned.load() << '\n';
  metric("haarcast_render_threads_stuck", "gauge",
         "Render threads left behind inside a render that has not returned (abandoned frames).");
  out << "haarcast_render_threads_stuck " << renderThreadsStuck.load() << '\n';
  metric("haarcast_frame_deadline_seconds", "gauge", "A frame rendering longer than this is abandoned (0 = none).");
  out << "haarcast_frame_deadline_seconds " << frameDeadlineSeconds.load() << '\n';

  std::lock_guard lock(mutex_);
  metric("haarcast_stage_seconds", "summary", "Time per frame stage, summed over frames.");
  for (const auto& [name, sc] : stages_) {
    char sum[64];
    std::snprintf(sum, sizeof sum, "%.9g", sc.first);
    out << "haarcast_stage_seconds_sum{stage=\"" << name << "\"} " << sum << '\n';
    out << "haarcast_stage_seconds_count{stage=\"" << name << "\"} " << sc.second << '\n';
  }
  metric("haarcast_device_healthy", "gauge",
         "1 while a device rendered on is healthy, 0 while a frame abandoned on it has not returned (its frames fail).");
  for (const DeviceHealth& d : devices_) {
    out << "haarcast_device_healthy{backend=\"" << labelValue(d.backend) << "\",device=\"" << labelValue(d.device)
        << "\"} " << (d.healthy ? 1 : 0) << '\n';
  }
  metric("haarcast_errors_total", "counter", "Protocol errors sent to clients, by code.");
  for (const auto& [code, n] : errors_) out << "haarcast_errors_total{code=\"" << code << "\"} " << n << '\n';
  for (const Family& f : kFamilies) {
    metric(f.name, "counter", f.help);
    const auto it = labelled_.find(std::string_view(f.name));
    if (it == labelled_.end()) continue;
    for (const auto& [label, n] : it->second) out << f.name << '{' << f.label << "=\"" << label << "\"} " << n << '\n';
  }
  return out.str();
}

}  // namespace haarcast::net
