#include "haarcast/client/run_stats.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace haarcast::client {

double quantile(std::vector<double> values, double q) {
  if (!(q >= 0.0 && q <= 1.0)) throw std::invalid_argument("quantile: q must be in [0, 1], got " + std::to_string(q));
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double rank = q * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(rank));
  const auto hi = std::min(lo + 1, values.size() - 1);
  const double frac = rank - static_cast<double>(lo);
  return values[lo] + (values[hi] - values[lo]) * frac;
}

namespace {

double mean(const std::vector<double>& v) {
  return v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
}

double ratio(double num, double den) { return den > 0.0 ? num / den : 0.0; }

nlohmann::json latencyFields(const std::vector<double>& latency) {
  return {
      {"latency_ms_p50", quantile(latency, 0.50)},
      {"latency_ms_p90", quantile(latency, 0.90)},
      {"latency_ms_p99", quantile(latency, 0.99)},
      {"latency_ms_mean", mean(latency)},
      {"latency_ms_max", latency.empty() ? 0.0 : *std::max_element(latency.begin(), latency.end())},
  };
}

}  // namespace

std::optional<double> SessionStats::serverFps() const {
  if (!firstStats || !lastStats || !(lastStats->first > firstStats->first)) return std::nullopt;
  const double frames = static_cast<double>(lastStats->second) - static_cast<double>(firstStats->second);
  return std::max(0.0, frames) / (lastStats->first - firstStats->first);
}

nlohmann::json summaryJson(const RunSummary& run) {
  std::uint64_t frames = 0, dropped = 0, errors = 0, payload = 0, wire = 0, blank = 0, extra = 0, failed = 0;
  std::uint64_t clippedFrames = 0, undecoded = 0, keyframeRequests = 0;
  double clippedMax = -1.0;
  std::vector<double> latency, server;
  std::map<std::string, std::vector<double>> stages;
  nlohmann::json perClient = nlohmann::json::array();
  for (std::size_t i = 0; i < run.sessions.size(); ++i) {
    const SessionStats& s = run.sessions[i];
    frames += s.frames;
    dropped += s.dropped;
    errors += s.errors;
    payload += s.payloadBytes;
    wire += s.wireBytes;
    blank += s.blankFrames;
    clippedFrames += s.clippedFrames;
    undecoded += s.undecodedFrames;
    keyframeRequests += s.keyframeRequests;
    clippedMax = std::max(clippedMax, s.clippedFractionMax);
    extra += s.extraFrames;
    failed += s.failure.empty() ? 0 : 1;
    latency.insert(latency.end(), s.latencyMs.begin(), s.latencyMs.end());
    server.insert(server.end(), s.serverMs.begin(), s.serverMs.end());
    for (const auto& [name, ms] : s.stageMs) stages[name].insert(stages[name].end(), ms.begin(), ms.end());
    nlohmann::json c = {
        {"client", i},
        {"frames", s.frames},
        {"fps", ratio(static_cast<double>(s.frames), s.lastFrameSeconds - s.firstPoseSeconds)},
        {"bytes_per_frame", ratio(static_cast<double>(s.payloadBytes), static_cast<double>(s.frames))},
        {"dropped", s.dropped},
        {"errors", s.errors},
        {"undecoded_frames", s.undecodedFrames},
        {"keyframe_requests", s.keyframeRequests},
        {"server_fps", s.serverFps() ? nlohmann::json(*s.serverFps()) : nlohmann::json(nullptr)},
        {"exposure_stops", s.lastExposureStops},
        {"failure", s.failure},
    };
    c.update(latencyFields(s.latencyMs));
    perClient.push_back(std::move(c));
  }
  const double f = static_cast<double>(frames);
  nlohmann::json out = {
      {"frames", frames},
      {"fps", ratio(f, run.wallSeconds)},
      {"bytes_per_frame", ratio(static_cast<double>(payload), f)},
      {"wire_bytes_per_frame", ratio(static_cast<double>(wire), f)},
      {"kbit_per_s", ratio(static_cast<double>(wire) * 8.0 / 1000.0, run.wallSeconds)},
      {"server_ms_p50", quantile(server, 0.5)},
      {"dropped", dropped},
      {"extra_frames", extra},
      {"errors", errors},
      {"blank_frames", blank},
      {"clipped_frames", clippedFrames},
      {"clipped_fraction_max", clippedMax < 0.0 ? nlohmann::json(nullptr) : nlohmann::json(clippedMax)},
      {"undecoded_frames", undecoded},
      {"keyframe_requests", keyframeRequests},
      {"failed_clients", failed},
      {"encoding", run.encoding},
      {"width", run.width},
      {"height", run.height},
      {"clients", run.sessions.size()},
      {"wall_s", run.wallSeconds},
      {"per_client", std::move(perClient)},
  };
  out.update(latencyFields(latency));
  nlohmann::json stageMeans = nlohmann::json::object();
  for (const auto& [name, ms] : stages) stageMeans[name] = mean(ms);
  out["stage_ms_mean"] = std::move(stageMeans);
  return out;
}

}  // namespace haarcast::client
