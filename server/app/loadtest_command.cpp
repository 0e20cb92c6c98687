// `haarcast loadtest`: per rotation method, client count, frame size and
// encoding, N sessions play an orbit + spin + light path against a server for
// a fixed time; the report puts fps, latency, bandwidth, storage and the PRT
// download baseline side by side (docs/loadtest.md).
#include "loadtest_command.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <boost/asio/io_context.hpp>

#include "app_paths.h"
#include "haarcast/backends/backends.h"
#include "haarcast/client/client_options.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/renderer.h"
#include "list_flags.h"
#include "loadtest_progress.h"
#include "loadtest_report.h"
#include "loadtest_server.h"
#include "loadtest_storage.h"
#include "haarcast/client/pose_path.h"
#include "progress.h"
#include "report_figures.h"
#include "haarcast/client/session.h"
#include "haarcast/wire/encoding_name.h"

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct LoadtestArgs {
  std::string url, token, backend;
  std::string methods = "fused,haar,spatial,matrix,table";
  std::string clients = "1,4,16";
  std::string sizes = "256";
  std::string encodings = "jpeg";
  double seconds = 10.0;
  unsigned warmup = 1;
  int level = 4;
  int storageLevel = 6;
  double fpsCap = 30.0;
  double timeout = 900.0;
  std::string out = "build/loadtest";
  std::string cacheDir;
  bool quick = false;
};

// Poses in one turn of the path (orbit, spin and light each turn 360° over
// it): at 30 fps one turn takes 8 s; the path cycles in longer runs.
constexpr std::uint64_t kPathPoses = 240;

// --quick: what the test suite runs (docs/loadtest.md "--quick").
constexpr const char* kQuickMethods = "fused,haar,table";
// More clients than the default per-address caps (8 waiting for a Hello):
// the local server must be started with caps that fit.
constexpr const char* kQuickClients = "1,10";
constexpr const char* kQuickSizes = "32";
constexpr double kQuickSeconds = 2.0;
constexpr int kQuickLevel = 4;

// The renderer options `haarcast serve` gives a session of this method and
// level (serve_command.cpp: RenderOptions defaults, the cache folder, k =
// its default 256, antialias auto = on for the CPU backend).
render::RenderOptions serverOptions(const LoadtestArgs& a, int level, RotationMethod method) {
  render::RenderOptions o;
  o.level = level;
  o.method = method;
  o.cacheDir = cacheDirFromFlag(a.cacheDir);
  o.antialias = true;
  return o;
}

struct Plan {
  std::vector<RotationMethod> methods;
  std::vector<int> clients;
  std::vector<std::pair<int, int>> sizes;
  std::vector<std::pair<std::string, v1::Encoding>> encodings;
};

Plan plan(const LoadtestArgs& a) {
  Plan p;
  p.methods = parseMethodList(a.methods, "--methods", false);
  p.clients = parseIntList(a.clients, "--clients", 1, 256);
  p.sizes = parseSizeList(a.sizes, "--sizes");
  // The client's encoding names (jpeg, png, raw, exr, h264): one spelling
  // for haarcast-client --encoding and this report.
  for (const auto& e : splitList(a.encodings, "--encodings")) {
    const v1::Encoding encoding = client::parseEncoding(e);
    p.encodings.emplace_back(wire::encodingName(encoding), encoding);
  }
  if (a.level < render::kMinRenderLevel || a.level > render::kMaxRenderLevel ||
      a.storageLevel < render::kMinRenderLevel || a.storageLevel > render::kMaxRenderLevel) {
    throw std::invalid_argument("--level and --storage-level must be in " + std::to_string(render::kMinRenderLevel) +
                                ".." + std::to_string(render::kMaxRenderLevel));
  }
  if (!(a.seconds > 0.0)) throw std::invalid_argument("--seconds must be positive");
  if (!a.backend.empty()) backends::checkBuilt(a.backend, "--backend");
  return p;
}

// One run: `clients` sessions on one io_context until each has played its
// time and received its last frame.
std::vector<client::SessionStats> drive(const client::SessionConfig& base, int clients, std::string& device,
                                        LoadtestProgress& progress) {
  boost::asio::io_context io;
  std::vector<client::SessionStats> stats(static_cast<std::size_t>(clients));
  std::vector<client::Session> sessions;
  sessions.reserve(stats.size());
  for (std::size_t i = 0; i < stats.size(); ++i) {
    client::SessionConfig config = base;
    config.hello.set_client_name("haarcast-loadtest/" + std::to_string(i));
    config.runStart = Clock::now();
    sessions.emplace_back(io, i, std::move(config), stats[i], [](const client::FrameEvent&) {},
                          [&progress](const std::string& line) { progress.message(line); });
    sessions.back().start();
  }
  io.run();
  if (!sessions.empty()) device = sessions.front().welcome().device();
  return stats;
}

std::string commandLine(const LoadtestArgs& a) {
  std::string c = "haarcast loadtest";
  if (a.quick) c += " --quick";
  if (!a.url.empty()) c += " --url " + a.url;
  c += " --methods " + a.methods + " --clients " + a.clients + " --sizes " + a.sizes + " --encodings " + a.encodings;
  char b[160];
  std::snprintf(b, sizeof b, " --level %d --storage-level %d --seconds %g --warmup %u --fps-cap %g", a.level,
                a.storageLevel, a.seconds, a.warmup, a.fpsCap);
  return c + b + (a.backend.empty() ? "" : " --backend " + a.backend) + " --out " + a.out;
}

int run(const LoadtestArgs& a) {
  const Plan p = plan(a);
  installInterruptHandler();
  const auto t0 = Clock::now();
  StderrProgress stages("[loadtest] ");
  const render::Scene scene = render::defaultScene();

  LoadtestReport report;
  report.command = commandLine(a);
  report.level = a.level;
  report.seconds = a.seconds;
  report.warmupPoses = a.warmup;
  report.fpsCap = a.fpsCap;
  report.machine = machineInfo();

  // Storage first, in this process and before any run: the server then finds
  // the slice tables and visibility in the shared cache.
  // splitsum too, always: its lobes are the floor of what a method can keep.
  std::vector<RotationMethod> sized = p.methods;
  for (RotationMethod m : {RotationMethod::Haar, RotationMethod::Table, RotationMethod::Splitsum}) {
    if (std::find(sized.begin(), sized.end(), m) == sized.end()) sized.push_back(m);
  }
  // At the runs' level: every run's method, haar, table and splitsum (the storage
  // figure reuses these when the levels agree) and the PRT baselines.
  std::vector<RotationMethod> atRunLevel = sized;
  for (RotationMethod m : kPrtBaselines) {
    if (std::find(atRunLevel.begin(), atRunLevel.end(), m) == atRunLevel.end()) atRunLevel.push_back(m);
  }
  const render::RenderOptions runOptions = serverOptions(a, a.level, kDefaultPixelMethod);
  report.shared = sharedStorage(render::prepareScene(scene, runOptions, stages.callback()));
  report.runStorage = methodStorage(scene, runOptions, atRunLevel, stages.callback());
  report.storage = a.storageLevel == a.level ? report.runStorage
                                             : methodStorage(scene, serverOptions(a, a.storageLevel, kDefaultPixelMethod),
                                                             sized, stages.callback());
  report.coefficientSource =
      "a frame of the same size and level rendered here by the CPU backend at the scene's own view (the path's "
      "first pose), Frame::coefficientBytes; the server does not send it";
  report.figuresSource = a.url.empty() ? "/proc of the local server process"
                                       : "the server's /metrics process_cpu_seconds_total and process_resident_memory_bytes "
                                         "(null when it does not export them)";

  const client::PosePath path = client::PosePath::orbit({.orbitDegrees = 360.0, .spinDegrees = 360.0, .lightDegrees = 360.0});
  const std::size_t total = p.methods.size() * p.clients.size() * p.sizes.size() * p.encodings.size();
  LoadtestProgress progress(total);
  std::size_t k = 0;
  bool ok = true;
  for (const RotationMethod method : p.methods) {
    const std::string mname(methodName(method));
    // Coefficient bytes per frame, per size, from a local frame (before the
    // server starts, so it does not compete with a run).
    std::map<std::pair<int, int>, std::size_t> coefficientBytes;
    {
      auto renderer = render::makeCpuRenderer(scene, serverOptions(a, a.level, method), stages.callback());
      for (const auto& [w, h] : p.sizes) {
        render::FrameRequest request;
        request.width = w, request.height = h, request.camera = scene.camera, request.linearImage = false;
        coefficientBytes[{w, h}] = renderer->render(request).coefficientBytes;
      }
    }
    // A fresh local server per method: its RSS is this method's alone.
    std::unique_ptr<LocalServer> server;
    client::SessionConfig base;
    if (a.url.empty()) {
      // Every client comes from 127.0.0.1: the per-address caps must fit
      // the largest run, or its clients past the pre-Hello cap are refused;
      // and the previous run's clients may still be closing when the next
      // run's connect (a busy machine closes them late), so room for both.
      const std::string perAddress = std::to_string(2 * *std::max_element(p.clients.begin(), p.clients.end()));
      const std::string sessions = std::to_string(std::max(64, std::stoi(perAddress)));
      std::vector<std::string> extra = {"--max-level",
                                        std::to_string(std::max(a.level, 6)),
                                        "--max-sessions",
                                        sessions,
                                        "--max-sessions-per-address",
                                        perAddress,
                                        "--max-connections-per-address",
                                        perAddress,
                                        "--max-pending-per-address",
                                        perAddress,
                                        "--max-pending",
                                        sessions};
      if (!a.cacheDir.empty()) extra.insert(extra.end(), {"--cache-dir", a.cacheDir});
      if (!a.backend.empty()) extra.insert(extra.end(), {"--backend", a.backend});
      server = std::make_unique<LocalServer>(extra, 60.0);
      base.url = client::parseWsUrl("ws://127.0.0.1:" + std::to_string(server->port()) + "/ws");
      report.server = "a local `haarcast serve` child on 127.0.0.1 (one per method)";
    } else {
      base.url = client::parseWsUrl(a.url);
      report.server = a.url;
    }
    auto figures = [&]() { return server ? server->figures() : fetchMetricsFigures(base.url.host, base.url.port); };
    base.token = a.token;
    base.path = &path;
    base.frames = kPathPoses;
    base.warmup = a.warmup;
    base.durationSeconds = a.seconds;
    base.timeoutSeconds = a.timeout;
    auto& hello = base.hello;
    hello.set_protocol_version(v1::PROTOCOL_VERSION_1);
    hello.set_fps_cap(a.fpsCap);
    hello.mutable_settings()->set_method(client::parseMethod(mname));
    hello.mutable_settings()->set_level(static_cast<std::uint32_t>(a.level));
    if (!a.backend.empty()) hello.mutable_settings()->set_backend(a.backend == render::kCpuBackend ? v1::BACKEND_CPU : v1::BACKEND_VULKAN);
    for (const int clients : p.clients) {
      for (const auto& [w, h] : p.sizes) {
        for (const auto& [ename, encoding] : p.encodings) {
          hello.set_width(static_cast<std::uint32_t>(w));
          hello.set_height(static_cast<std::uint32_t>(h));
          hello.set_encoding(encoding);
          char label[128];
          std::snprintf(label, sizeof label, "%s, %d client%s, %d×%d %s", mname.c_str(), clients, clients == 1 ? "" : "s",
                        w, h, ename.c_str());
          progress.startRun(k++, label, a.seconds);
          const ProcessFigures before = figures();
          const auto runStart = Clock::now();
          RunRecord record;
          const auto stats = drive(base, clients, report.device, progress);
          record.wallSeconds = std::chrono::duration<double>(Clock::now() - runStart).count();
          const ProcessFigures after = figures();
          progress.endRun();
          record.figures = summarizeRun(stats);
          record.figures.method = mname;
          record.figures.width = static_cast<std::uint32_t>(w);
          record.figures.height = static_cast<std::uint32_t>(h);
          record.figures.encoding = ename;
          record.figures.level = a.level;
          record.storedBytes = report.runStorage.storedBytes.at(method);
          record.coefficientBytesPerFrame = coefficientBytes.at({w, h});
          if (before.cpuSeconds && after.cpuSeconds) record.serverCpuSeconds = *after.cpuSeconds - *before.cpuSeconds;
          record.serverRssBytes = after.rssBytes;
          record.serverPeakRssBytes = after.peakRssBytes;
          const RunFigures& f = record.figures;
          ok = ok && f.failures.empty() && f.frames > 0;
          char line[400];
          std::snprintf(line, sizeof line, "%s: %.2f fps/client (median), latency p50 %.0f ms, %.3f Mbit/s per client%s",
                        label, f.fpsMedian, f.latencyP50, f.bitsPerSecondPerClient / 1e6,
                        f.failures.empty() ? "" : ", FAILED");
          progress.message(line);
          report.runs.push_back(std::move(record));
        }
      }
    }
    if (server) {
      if (const int rc = server->stop(); rc != 0) progress.message("the local server exited with status " + std::to_string(rc));
    }
  }
  report.wallSeconds = std::chrono::duration<double>(Clock::now() - t0).count();

  fs::create_directories(a.out);
  const fs::path json = fs::path(a.out) / "report.json";
  std::ofstream(json) << toJson(report).dump(2) << '\n';
  const FigureRun drawn = drawReportFigures(json);
  // The reported wall time is the reader's wait, figures included.
  report.figuresSeconds = drawn.seconds;
  report.wallSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
  std::ofstream(json) << toJson(report).dump(2) << '\n';
  std::string note;
  if (drawn.status == FigureRun::Status::Drawn) {
    for (const char* f : kLoadtestFigures) note += std::string("![") + f + "](" + f + ")\n\n";
  } else {
    note = "Not drawn: " + drawn.problem + ".\n";
    progress.message("figures not drawn: " + drawn.problem);
  }
  std::ofstream(fs::path(a.out) / "report.md") << toMarkdown(report, note);
  progress.message("wrote " + json.string() + " and report.md in " + formatDuration(report.wallSeconds));
  return ok ? 0 : 1;
}

}  // namespace

std::function<int()> addLoadtestCommand(CLI::App& app) {
  auto a = std::make_shared<LoadtestArgs>();
  auto* c = app.add_subcommand("loadtest", "Sessions per method × clients × size × encoding: fps, latency, bandwidth, "
                                           "storage and the PRT download baseline");
  c->add_option("--url", a->url, "ws://HOST:PORT of a running server (default: start one on loopback)");
  c->add_option("--token", a->token, "Bearer token of that server");
  auto* methods = c->add_option("--methods", a->methods, "Per-pixel methods, comma-separated: " + pixelMethodNames())
                      ->capture_default_str();
  auto* clients = c->add_option("--clients", a->clients, "Client counts, comma-separated")->capture_default_str();
  auto* sizes = c->add_option("--sizes", a->sizes, "Frame sizes, comma-separated: N for N×N, or WxH")->capture_default_str();
  c->add_option("--encodings", a->encodings, "Encodings, comma-separated: jpeg, png, raw, exr, h264")->capture_default_str();
  auto* seconds = c->add_option("--seconds", a->seconds, "Measured seconds per run (after the warm-up)")->capture_default_str();
  c->add_option("--warmup", a->warmup, "Poses per client played first and left out (the renderer is built before Welcome)")
      ->capture_default_str();
  auto* level = c->add_option("--level", a->level, "Map level the sessions render at")->capture_default_str();
  c->add_option("--storage-level", a->storageLevel, "Level of the storage figure (stored_bytes per method)")
      ->capture_default_str();
  c->add_option("--fps-cap", a->fpsCap, "Frames per second each session asks for")->capture_default_str();
  c->add_option("--timeout", a->timeout, "Seconds to wait for a Welcome or any one frame")->capture_default_str();
  c->add_option("--backend", a->backend, backends::availableText() + " (default: the server's)");
  c->add_option("--cache-dir", a->cacheDir, "Slice-table and visibility cache, shared with the local server");
  c->add_option("--out", a->out, "Folder for report.json, report.md and the figures")->capture_default_str();
  char quick[200];
  std::snprintf(quick, sizeof quick,
                "A short run for the test suite: --methods %s --clients %s --sizes %s --level %d --seconds %g "
                "(flags given explicitly win)",
                kQuickMethods, kQuickClients, kQuickSizes, kQuickLevel, kQuickSeconds);
  c->add_flag("--quick", a->quick, quick);
  return [c, a, methods, clients, sizes, seconds, level]() {
    if (!c->parsed()) return -1;
    if (a->quick) {
      if (methods->count() == 0) a->methods = kQuickMethods;
      if (clients->count() == 0) a->clients = kQuickClients;
      if (sizes->count() == 0) a->sizes = kQuickSizes;
      if (seconds->count() == 0) a->seconds = kQuickSeconds;
      if (level->count() == 0) a->level = kQuickLevel;
    }
    return run(*a);
  };
}

}  // namespace haarcast::app
