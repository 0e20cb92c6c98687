// What one client session measured, and the summary of a run over one or
// more sessions: the numbers `--json` prints. Pure, tested without sockets.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace haarcast::client {

// The q-quantile (q in [0, 1]) with linear interpolation between the two
// nearest ranks (numpy's default), so p50 of {1, 2, 3, 4} is 2.5. An empty
// sample gives 0. Throws std::invalid_argument for q outside [0, 1].
double quantile(std::vector<double> values, double q);

struct SessionStats {
  std::uint64_t frames = 0;         // frames that answered one of our poses
  std::uint64_t posesSent = 0;
  std::uint64_t dropped = 0;        // poses sent that no frame answered (superseded)
  std::uint64_t extraFrames = 0;    // frames answering no pose of ours (e.g. pose 0)
  std::uint64_t errors = 0;         // Error messages received, fatal or not
  std::uint64_t payloadBytes = 0;   // Frame.data bytes of the counted frames
  std::uint64_t wireBytes = 0;      // whole WebSocket messages of those frames
  std::uint64_t blankFrames = 0;    // only counted with --check-not-blank
  std::uint64_t clippedFrames = 0;  // over --max-clipped
  // H.264 only: frames the session's decoder could not decode (a delta
  // frame without its keyframe), counted or not, and the poses sent with
  // PoseUpdate.keyframe to recover.
  std::uint64_t undecodedFrames = 0;
  std::uint64_t keyframeRequests = 0;
  double clippedFractionMax = -1.0; // the most blown-out frame's share of pixels at 255; < 0: not measured
  double lastExposureStops = 0.0;   // Frame.exposure_stops of the last frame
  double firstPoseSeconds = 0.0;    // steady-clock times, from the run's start
  double lastFrameSeconds = 0.0;
  std::vector<double> latencyMs;    // pose sent → its frame received, per frame
  std::vector<double> serverMs;     // the server's own pose → frame queued
  // The server's per-stage timings (Frame.timings), by stage name.
  std::map<std::string, std::vector<double>> stageMs;
  std::string failure;              // non-empty: why the session failed
  // The server's Stats messages: the first and the last, as (seconds from
  // the run's start when it arrived, its frames_sent), and the last one's
  // session count.
  std::optional<std::pair<double, std::uint64_t>> firstStats, lastStats;
  std::uint32_t serverSessions = 0;

  // The frames the server says it sent between the first and the last
  // Stats, over the time between them: its frame rate through the run
  // (each Stats' own fps covers its last second only, 0 once the poses
  // stop). nullopt with fewer than two Stats (a run shorter than the
  // server's Stats period).
  std::optional<double> serverFps() const;
};

struct RunSummary {
  std::string encoding;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<SessionStats> sessions;
  double wallSeconds = 0.0;  // first pose of any client → last frame of any client
};

// The `--json` object: frames, fps, latency_ms_p50/p90/p99/mean/max,
// bytes_per_frame, wire_bytes_per_frame, dropped, errors, undecoded_frames,
// keyframe_requests, encoding, size,
// clients, the server's stage timings (mean ms per stage name, under
// "stage_ms_mean"), and per-client figures under "per_client". fps is total frames
// over the wall time: with N clients it is the server's aggregate rate.
nlohmann::json summaryJson(const RunSummary& run);

}  // namespace haarcast::client
