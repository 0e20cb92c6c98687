#include "loadtest_report.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace haarcast::app {
namespace {

std::string name(RotationMethod m) { return std::string(methodName(m)); }

const char* paper(RotationMethod m) {
  return m == RotationMethod::Table ? "Ng, Ramamoorthi, Hanrahan 2004: pre-rotated BRDF slices"
                                    : "Wang, Ng, Ramamoorthi 2006: rotation matrices";
}

template <class T>
nlohmann::json orNull(const std::optional<T>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

std::string megabytes(double bytes) {
  char b[32];
  std::snprintf(b, sizeof b, bytes >= 1e8 ? "%.0f MB" : bytes >= 1e6 ? "%.1f MB" : "%.3f MB", bytes / 1e6);
  return b;
}

std::string fixed(double v, const char* format) {
  char b[48];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

}  // namespace

RunFigures summarizeRun(const std::vector<client::SessionStats>& sessions) {
  if (sessions.empty()) throw std::invalid_argument("loadtest: a run needs at least one session");
  RunFigures f;
  std::vector<double> fps, bps, latency;
  std::uint64_t payload = 0;
  for (std::size_t i = 0; i < sessions.size(); ++i) {
    const client::SessionStats& s = sessions[i];
    if (!s.failure.empty()) {
      std::string why = "client ";
      why.append(std::to_string(i)).append(": ").append(s.failure);
      f.failures.push_back(std::move(why));
    }
    // The client's own window: its first measured pose to its last frame.
    const double window = s.lastFrameSeconds - s.firstPoseSeconds;
    const bool measured = s.frames > 0 && window > 0.0;
    fps.push_back(measured ? static_cast<double>(s.frames) / window : 0.0);
    bps.push_back(measured ? static_cast<double>(s.wireBytes) * 8.0 / window : 0.0);
    latency.insert(latency.end(), s.latencyMs.begin(), s.latencyMs.end());
    f.frames += s.frames;
    payload += s.payloadBytes;
  }
  f.clients = static_cast<std::uint32_t>(sessions.size());
  f.fpsMin = std::numeric_limits<double>::infinity();
  for (double v : fps) f.fpsMin = std::min(f.fpsMin, v), f.fpsMax = std::max(f.fpsMax, v);
  f.fpsMedian = client::quantile(fps, 0.5);
  f.latencyP50 = client::quantile(latency, 0.50);
  f.latencyP99 = client::quantile(latency, 0.99);
  double sum = 0.0;
  for (double b : bps) sum += b, f.bitsPerSecondPerClientMax = std::max(f.bitsPerSecondPerClientMax, b);
  f.bitsPerSecondPerClient = sum / static_cast<double>(bps.size());
  f.bytesPerFrame = f.frames ? static_cast<double>(payload) / static_cast<double>(f.frames) : 0.0;
  return f;
}

std::map<RotationMethod, PrtBaseline> prtBaselines(const LoadtestReport& r) {
  double fastest = 0.0;
  for (const RunRecord& run : r.runs) fastest = std::max(fastest, run.figures.bitsPerSecondPerClient);
  std::map<RotationMethod, PrtBaseline> out;
  for (const RotationMethod m : kPrtBaselines) {
    const auto it = r.runStorage.storedBytes.find(m);
    if (it == r.runStorage.storedBytes.end()) continue;
    PrtBaseline b;
    b.bytes = prtDownloadBytes(it->second, r.shared);
    b.atBitsPerSecond = fastest;
    b.breakEvenSeconds = fastest > 0.0 ? breakEvenSeconds(b.bytes, fastest) : 0.0;
    out[m] = b;
  }
  return out;
}

nlohmann::json toJson(const LoadtestReport& r) {
  nlohmann::json j;
  j["kind"] = "loadtest";  // plot_report.py draws the loadtest figures for this kind
  j["command"] = r.command;
  j["server"] = {{"where", r.server}, {"device", r.device}, {"process_figures_from", r.figuresSource}};
  j["machine"] = toJson(r.machine);
  j["level"] = r.level;
  j["seconds_per_run"] = r.seconds;
  j["warmup_poses_per_client"] = r.warmupPoses;
  j["fps_cap"] = r.fpsCap;
  j["wall_seconds"] = r.wallSeconds;
  j["figures_seconds"] = r.figuresSeconds;
  j["coefficient_bytes_per_frame_from"] = r.coefficientSource;
  const auto baselines = prtBaselines(r);
  j["runs"] = nlohmann::json::array();
  for (const RunRecord& run : r.runs) {
    const RunFigures& f = run.figures;
    nlohmann::json row = {
        {"method", f.method},
        {"clients", f.clients},
        {"width", f.width},
        {"height", f.height},
        {"encoding", f.encoding},
        {"level", f.level},
        {"fps_per_client", {{"min", f.fpsMin}, {"median", f.fpsMedian}, {"max", f.fpsMax}}},
        {"latency_ms", {{"p50", f.latencyP50}, {"p99", f.latencyP99}}},
        {"bits_per_second_per_client", f.bitsPerSecondPerClient},
        {"bits_per_second_per_client_max", f.bitsPerSecondPerClientMax},
        {"bytes_per_frame", f.bytesPerFrame},
        {"frames", f.frames},
        {"stored_bytes", run.storedBytes},
        {"coefficient_bytes_per_frame", run.coefficientBytesPerFrame},
        {"server_cpu_seconds", orNull(run.serverCpuSeconds)},
        {"server_rss_bytes", orNull(run.serverRssBytes)},
        {"server_peak_rss_bytes", orNull(run.serverPeakRssBytes)},
        {"wall_seconds", run.wallSeconds},
        {"failures", f.failures},
    };
    nlohmann::json breakEven = nlohmann::json::object();
    for (const auto& [m, b] : baselines) {
      breakEven[name(m)] = f.bitsPerSecondPerClient > 0.0 ? nlohmann::json(breakEvenSeconds(b.bytes, f.bitsPerSecondPerClient))
                                                           : nlohmann::json(nullptr);
    }
    row["break_even_seconds"] = breakEven;
    j["runs"].push_back(row);
  }
  auto storageJson = [](const MethodStorage& s) {
    nlohmann::json o = {{"level", s.level}, {"stored_bytes", nlohmann::json::object()},
                        {"precompute_seconds", nlohmann::json::object()}};
    for (const auto& [m, bytes] : s.storedBytes) o["stored_bytes"][name(m)] = bytes;
    for (const auto& [m, seconds] : s.precomputeSeconds) o["precompute_seconds"][name(m)] = seconds;
    return o;
  };
  j["stored_bytes_definition"] =
      "the BRDF coefficient data each method holds for the scene, summed over objects and colour channels: "
      "makeRotator(method, slices)->storedBytes() (the unrotated slices plus the method's precomputation; "
      "table's pre-rotated copies replace the slices; what rotators share, matrix's elevation matrices, "
      "counted once: SliceRotator::sharedBytes) and, for fused, the slices in pixel form "
      "(PixelSlices::storedBytes). Visibility, light and meshes are the same for every method: see shared_bytes.";
  j["storage"] = storageJson(r.storage);
  j["storage_at_run_level"] = storageJson(r.runStorage);
  j["shared_bytes"] = {{"level", r.shared.level},
                       {"visibility", r.shared.visibilityBytes},
                       {"light", r.shared.lightBytes},
                       {"meshes", r.shared.meshBytes},
                       {"slice_tables", r.shared.sliceTableBytes}};
  j["prt_baseline"] = nlohmann::json::object();
  for (const auto& [m, b] : baselines) {
    j["prt_baseline"][name(m)] = {{"bytes", b.bytes},
                                  {"level", r.runStorage.level},
                                  {"paper", paper(m)},
                                  {"includes", "the method's BRDF data + visibility + light + meshes"},
                                  {"break_even_seconds", b.breakEvenSeconds},
                                  {"at_bits_per_second", b.atBitsPerSecond}};
  }
  j["figures"] = nlohmann::json::array();
  for (const char* file : kLoadtestFigures) j["figures"].push_back(file);
  return j;
}

std::string toMarkdown(const LoadtestReport& r, const std::string& figuresNote) {
  std::string md = "# haarcast loadtest\n\n";
  md += "Command: `" + r.command + "`  \n";
  md += "Server: " + r.server + (r.device.empty() ? "" : ", device \"" + r.device + "\"") + "  \n";
  md += "Machine: " + describeMachine(toJson(r.machine)) + ", load average at start " + r.machine.loadAverage +
        " (other work on the machine slows every figure here)  \n";
  md += "Level " + std::to_string(r.level) + ", " + fixed(r.seconds, "%.1f") + " s per run after " +
        std::to_string(r.warmupPoses) + " warm-up pose(s) per client, fps cap " + fixed(r.fpsCap, "%.0f") +
        ", closed loop (one pose in flight per client); wall time " + fixed(r.wallSeconds, "%.0f") + " s, of which " +
        fixed(r.figuresSeconds, "%.1f") + " s drawing the figures.\n\n";

  const auto baselines = prtBaselines(r);
  md += "| method | clients | size | encoding | fps/client min / median / max | latency p50 / p99 (ms) | Mbit/s per client | "
        "stored bytes | coeff. bytes/frame | server CPU (s) | server RSS |";
  for (const auto& [m, b] : baselines) md += " break-even vs " + name(m) + " (s) |";
  md += "\n|---|---|---|---|---|---|---|---|---|---|---|";
  for (std::size_t i = 0; i < baselines.size(); ++i) md += "---|";
  md += "\n";
  for (const RunRecord& run : r.runs) {
    const RunFigures& f = run.figures;
    md += "| " + f.method + " | " + std::to_string(f.clients) + " | " + std::to_string(f.width) + "×" +
          std::to_string(f.height) + " | " + f.encoding + " | " + fixed(f.fpsMin, "%.2f") + " / " +
          fixed(f.fpsMedian, "%.2f") + " / " + fixed(f.fpsMax, "%.2f") + " | " + fixed(f.latencyP50, "%.0f") + " / " +
          fixed(f.latencyP99, "%.0f") + " | " + fixed(f.bitsPerSecondPerClient / 1e6, "%.3f") + " | " +
          std::to_string(run.storedBytes) + " | " + std::to_string(run.coefficientBytesPerFrame) + " | " +
          (run.serverCpuSeconds ? fixed(*run.serverCpuSeconds, "%.1f") : "null") + " | " +
          (run.serverRssBytes ? megabytes(static_cast<double>(*run.serverRssBytes)) : "null") + " |";
    for (const auto& [m, b] : baselines) {
      md.append(" ")
          .append(f.bitsPerSecondPerClient > 0.0 ? fixed(breakEvenSeconds(b.bytes, f.bitsPerSecondPerClient), "%.0f") : "–")
          .append(" |");
    }
    md += "\n";
    for (const std::string& why : f.failures) md += "\n> failed: " + why + "\n";
  }
  md += "\nfps and Mbit/s are per client, over each client's own window (first measured pose → last frame); "
        "Mbit/s counts Frame messages' WebSocket payloads. Latency is pose sent → its frame received, every frame "
        "of every client. Coefficient bytes per frame: " + r.coefficientSource + ". Server CPU: seconds used during "
        "the run; RSS: resident after it (" + r.figuresSource + ").\n\n";

  md += "## Storage and the PRT download baseline\n\n";
  md += "stored bytes = the BRDF coefficient data a method holds for this scene (all objects, all channels): "
        "`makeRotator(method, slices)->storedBytes()`, with what rotators share (matrix's elevation matrices) "
        "counted once, or for fused the slices in pixel form, for splitsum its lobes alone (64 bytes per θₒ "
        "sample: no slices).\n\n";
  md += "| method | stored bytes, level " + std::to_string(r.runStorage.level) + " | stored bytes, level " +
        std::to_string(r.storage.level) + " |\n|---|---|---|\n";
  for (const auto& [m, bytes] : r.storage.storedBytes) {
    const auto run = r.runStorage.storedBytes.find(m);
    md += "| " + name(m) + " | " + (run != r.runStorage.storedBytes.end() ? std::to_string(run->second) : "–") + " | " +
          std::to_string(bytes) + " |\n";
  }
  md += "\nShared by every method at level " + std::to_string(r.shared.level) + ": visibility " +
        std::to_string(r.shared.visibilityBytes) + " B, light " + std::to_string(r.shared.lightBytes) + " B, meshes " +
        std::to_string(r.shared.meshBytes) + " B.\n\n";
  md += "| baseline | paper | download (bytes) | break-even (s) at the fastest per-client stream |\n|---|---|---|---|\n";
  for (const auto& [m, b] : baselines) {
    md += "| " + name(m) + " | " + paper(m) + " | " + std::to_string(b.bytes) + " (" +
          megabytes(static_cast<double>(b.bytes)) + ") | " + fixed(b.breakEvenSeconds, "%.0f") + " at " +
          fixed(b.atBitsPerSecond / 1e6, "%.3f") + " Mbit/s |\n";
  }
  md += "\nThe download is what a client needs to render the scene itself at level " +
        std::to_string(r.runStorage.level) +
        ": the baseline's BRDF data, visibility, light and meshes. Break-even: download bytes · 8 / the stream's "
        "bits per second.\n\n## Figures\n\n" + figuresNote + "\n";
  return md;
}

}  // namespace haarcast::app
