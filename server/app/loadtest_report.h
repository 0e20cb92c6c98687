// `haarcast loadtest`'s figures per run and its report: report.json (the
// keys docs/loadtest.md lists) and report.md (a table, the PRT baseline, the
// figures). Pure: the sessions' statistics in, JSON and Markdown out, so the
// arithmetic (percentiles, rates, break-even) is tested without a server.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "loadtest_server.h"
#include "machine_info.h"
#include "loadtest_storage.h"
#include "haarcast/client/run_stats.h"

namespace haarcast::app {

// The baselines a client could download instead of streaming, with the
// paper each one follows.
inline constexpr RotationMethod kPrtBaselines[] = {RotationMethod::Table, RotationMethod::Matrix};

struct RunFigures {
  std::string method;
  std::uint32_t clients = 0;
  std::uint32_t width = 0, height = 0;
  std::string encoding;
  int level = 0;
  // Per client: frames / (last frame − first measured pose), in that client's
  // own window; min, median and max over the clients.
  double fpsMin = 0.0, fpsMedian = 0.0, fpsMax = 0.0;
  // Pose sent → the frame answering it received, every frame of every client.
  double latencyP50 = 0.0, latencyP99 = 0.0;
  // Frame messages' WebSocket payload bytes · 8 / the client's window, mean
  // and max over the clients.
  double bitsPerSecondPerClient = 0.0, bitsPerSecondPerClientMax = 0.0;
  double bytesPerFrame = 0.0;  // Frame.data, mean over every frame
  std::uint64_t frames = 0;
  std::vector<std::string> failures;  // "client K: why", one per failed session
};

// Throws std::invalid_argument when sessions is empty.
RunFigures summarizeRun(const std::vector<client::SessionStats>& sessions);

// Everything else a run row holds: measured around the run, or sized apart.
struct RunRecord {
  RunFigures figures;
  std::size_t storedBytes = 0;              // the method's BRDF data at the run's level
  std::size_t coefficientBytesPerFrame = 0;  // Frame::coefficientBytes of a local frame
  std::optional<double> serverCpuSeconds;    // during the run
  std::optional<std::uint64_t> serverRssBytes, serverPeakRssBytes;  // after it
  double wallSeconds = 0.0;                  // connect → last session closed
};

struct LoadtestReport {
  std::string command;          // as typed, for the report
  std::string server;           // "local child on 127.0.0.1:P" or the --url
  std::string device;           // Welcome.device
  std::string figuresSource;    // where server CPU and RSS came from
  std::string coefficientSource;  // where coefficient_bytes_per_frame came from
  int level = 0;
  double seconds = 0.0;
  std::uint32_t warmupPoses = 0;
  double fpsCap = 0.0;
  MachineInfo machine;          // CPU, cores, and /proc/loadavg at the start: the machine's other work
  std::vector<RunRecord> runs;
  MethodStorage runStorage;     // at the runs' level: stored_bytes of every run and the baselines
  MethodStorage storage;        // at the storage level (6 by default)
  SharedStorage shared;         // visibility, light, meshes at the runs' level
  double wallSeconds = 0.0;     // the whole command, the figures included
  double figuresSeconds = 0.0;  // of which drawing the figures
};

// The PRT download of a baseline at the runs' level, and the seconds of
// streaming at `bitsPerSecond` that cost as much.
struct PrtBaseline {
  std::size_t bytes = 0;
  double breakEvenSeconds = 0.0;
  double atBitsPerSecond = 0.0;  // the highest per-client rate measured: the earliest break-even
};
std::map<RotationMethod, PrtBaseline> prtBaselines(const LoadtestReport& report);

nlohmann::json toJson(const LoadtestReport& report);
// figuresNote: the figures' Markdown (images) or why there are none.
std::string toMarkdown(const LoadtestReport& report, const std::string& figuresNote);

// The figure files plot_report.py writes for a loadtest report.
inline constexpr const char* kLoadtestFigures[] = {"loadtest_bandwidth.png", "loadtest_fps.png", "loadtest_storage.png"};

}  // namespace haarcast::app
