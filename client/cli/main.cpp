// haarcast-client: the thin command-line client. Connects to `haarcast serve`,
// plays a scripted pose path, records the frames, and reports latency, fps and
// bytes per frame (a progress line on stderr, a --json summary on stdout).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>
#include <nlohmann/json.hpp>

#include "haarcast/client/build_progress.h"
#include "haarcast/client/client_options.h"
#include "haarcast/client/flag_suggest.h"
#include "haarcast/client/pose_path.h"
#include "haarcast/client/run_stats.h"
#include "haarcast/client/session.h"
#include "haarcast/wire/encoding_name.h"

namespace {

using namespace haarcast::client;
using Clock = std::chrono::steady_clock;

// The progress display on stderr: one line redrawn in place on a terminal,
// a line every tenth of the run otherwise (logs and CI). A total of 0 means
// unknown (--duration): a line every 10 frames, and no bar. Before the
// frames, the server's renderer build (build_progress.h), the same way.
class Progress {
 public:
  Progress(std::uint64_t total, bool quiet, bool perFrame)
      : total_(total),
        quiet_(quiet),
        perFrame_(perFrame),
        tty_(isatty(STDERR_FILENO) != 0),
        build_(tty_ && !perFrame, [](const std::string& text) {
          std::fputs(text.c_str(), stderr);
          std::fflush(stderr);
        }) {}

  // A BuildProgress of client `client`'s renderer; nullptr: it is ready.
  void build(std::size_t /*client: the sessions of a run share one build*/, const haarcast::v1::BuildProgress* p) {
    if (quiet_) return;
    const double now = std::chrono::duration<double>(Clock::now() - created_).count();
    if (!p) {
      build_.ready(now);
      return;
    }
    endFrameLine();
    build_.update(*p, now);
  }

  void frame(const FrameEvent& e) {
    ++done_;
    bytes_ += e.bytes;
    lastLatency_ = e.latencyMs;
    if (quiet_) return;
    build_.endLine();
    const auto now = Clock::now();
    if (done_ == 1) start_ = now;
    if (perFrame_) {
      std::fprintf(stderr, "client %zu pose %llu: %.1f ms, %zu bytes\n", e.client,
                   static_cast<unsigned long long>(e.pose), e.latencyMs, e.bytes);
      std::fflush(stderr);
      return;
    }
    if (tty_) {
      if (now - lastDraw_ < std::chrono::milliseconds(100) && done_ != total_) return;
      lastDraw_ = now;
      std::fprintf(stderr, "\r%s", line(now).c_str());
      lineOpen_ = true;
    } else {
      const std::uint64_t step = total_ == 0 ? 10 : std::max<std::uint64_t>(1, total_ / 10);
      if (done_ % step != 0 && done_ != total_) return;
      std::fprintf(stderr, "%s\n", line(now).c_str());
    }
    std::fflush(stderr);
  }

  // A message line (an error, a warning) must not be drawn over.
  void message(const std::string& text) {
    endLine();
    std::fprintf(stderr, "haarcast-client: %s\n", text.c_str());
    std::fflush(stderr);
  }

  void endLine() {
    build_.endLine();
    endFrameLine();
  }

 private:
  std::string line(Clock::time_point now) const {
    const double seconds = std::chrono::duration<double>(now - start_).count();
    const double fps = done_ > 1 && seconds > 0 ? static_cast<double>(done_ - 1) / seconds : 0.0;
    std::string bar;
    if (total_ > 0) {
      constexpr std::uint64_t kWidth = 24;
      const std::uint64_t filled = std::min(kWidth, kWidth * done_ / total_);
      bar = "[" + std::string(filled, '#') + std::string(kWidth - filled, '.') + "] ";
    }
    char text[200];
    std::snprintf(text, sizeof text, "%s%llu/%s  %6.1f fps  latency %7.1f ms  %7.1f KB/frame", bar.c_str(),
                  static_cast<unsigned long long>(done_), total_ > 0 ? std::to_string(total_).c_str() : "?", fps,
                  lastLatency_, static_cast<double>(bytes_) / 1000.0 / static_cast<double>(done_));
    return text;
  }

  void endFrameLine() {
    if (lineOpen_) std::fputc('\n', stderr);
    lineOpen_ = false;
  }

  std::uint64_t total_;
  bool quiet_;
  bool perFrame_;
  bool tty_;
  BuildProgressDisplay build_;
  Clock::time_point created_ = Clock::now();
  bool lineOpen_ = false;
  std::uint64_t done_ = 0;
  std::uint64_t bytes_ = 0;
  double lastLatency_ = 0.0;
  Clock::time_point start_ = Clock::now();
  Clock::time_point lastDraw_{};
};

// "0=phong:64" or "phong:64" (object 0) → (object, spec).
std::pair<std::uint32_t, std::string> parseMaterial(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos) return {0, text};
  try {
    std::size_t used = 0;
    const unsigned long index = std::stoul(text.substr(0, eq), &used);
    if (used != eq || index > 1000000) throw std::invalid_argument("");
    if (eq + 1 >= text.size()) throw std::invalid_argument("");
    return {static_cast<std::uint32_t>(index), text.substr(eq + 1)};
  } catch (const std::logic_error&) {
    throw std::invalid_argument("--material must be SPEC or OBJECT=SPEC, e.g. 1=ggx:0.3 (got \"" + text + "\")");
  }
}

int run(int argc, char** argv) {
  CLI::App app{"haarcast-client: plays a pose path against `haarcast serve` and measures the frames"};
  app.set_version_flag("--version", "haarcast-client 0.1.0 (protocol 1)");
  std::string url;
  std::uint64_t frames = 100;
  std::string size = "256x256";
  std::string encoding = "jpeg";
  std::string token;
  std::string outDir;
  double fpsCap = 0.0;
  unsigned quality = 0;
  H264Options h264;
  std::string method;
  std::string backend;
  std::string level;
  unsigned coefficients = 0;
  std::string scene;
  std::vector<std::string> materials;
  std::string pathFile;
  OrbitSweep sweep;
  unsigned clients = 1;
  unsigned inFlight = 1;
  unsigned warmup = 0;
  double duration = 0.0;
  double timeout = 30.0;
  bool json = false;
  bool checkNotBlank = false;
  std::string exposure = "auto";
  std::string tone;
  double maxClipped = -1.0;
  bool quiet = false;
  bool perFrame = false;

  app.add_option("url", url, "ws://HOST:PORT[/ws] of `haarcast serve`")->required();
  auto* framesOpt = app.add_option("--frames,-n", frames, "Poses to play, one frame each (default 100; a --path file's length)")
                        ->check(CLI::Range(std::uint64_t{1}, std::uint64_t{10000000}));
  app.add_option("--size", size, "WIDTHxHEIGHT of the frames")->capture_default_str();
  app.add_option("--encoding", encoding, "jpeg | png | raw | exr | h264")->capture_default_str();
  app.add_option("--token", token, "Bearer token, if the server was started with --token");
  app.add_option("--out", outDir, "Record every frame into this folder (client-K/ subfolders with --clients > 1)");
  app.add_option("--fps-cap", fpsCap, "Ask the server for at most this many frames per second (0 = its default)")
      ->check(CLI::Range(0.0, 1000.0));
  app.add_option("--quality", quality, "JPEG quality 1..100 (0 = the server's default)")->check(CLI::Range(0u, 100u));
  app.add_option("--bitrate", h264.bitrateKbps,
                 "H.264 bitrate cap in kbit/s (0 = the server's default; Welcome.limits has its maximum)")
      ->check(CLI::Range(0u, 10000000u));
  app.add_option("--keyframe-interval", h264.keyframeInterval,
                 "H.264 frames from one keyframe to the next (0 = the server's default)")
      ->check(CLI::Range(0u, 100000u));
  app.add_option("--method", method, "Per-pixel method: fused | haar | spatial | matrix | table | splitsum (default: the server's)");
  app.add_option("--backend", backend, "Backend: cpu | vulkan, one the server enables (default: the server's)")
      ->check(CLI::IsMember({"cpu", "vulkan"}));
  app.add_option("--level", level,
                 "Map level n, 2^n x 2^n, in the server's range (its Welcome.limits; a level outside it is "
                 "refused by name), every object at it; auto or auto:N: each "
                     "object at the level its material needs, N at most (fused); default: the server's");
  app.add_option("--exposure", exposure,
                 "auto (the whole frame metered, objects weighted 4×: log-average → 0.18, held down so the brightest 1% "
                 "does not clip; eased) or fixed stops, e.g. -1")
      ->capture_default_str();
  app.add_option("--tone", tone, "Tone curve: reinhard | aces | agx (default: the server's, reinhard)")
      ->check(CLI::IsMember({"reinhard", "aces", "agx"}));
  app.add_option("--max-clipped", maxClipped,
                 "Fail a frame with more than this fraction of pixels at 255 (blown out), e.g. 0.02; decodes every frame")
      ->check(CLI::Range(0.0, 1.0));
  app.add_option("--coefficients,-k", coefficients, "Light coefficients kept (0 = the server's default)");
  app.add_option("--scene", scene, "Scene name offered by the server (default: the server's)");
  app.add_option("--material", materials, "Material SPEC for object 0, or OBJECT=SPEC; repeatable");
  auto* pathOpt = app.add_option("--path", pathFile, "JSON file of poses (see docs/clients.md); overrides the sweep")
                      ->check(CLI::ExistingFile);
  auto* orbitOpt = app.add_option("--orbit", sweep.orbitDegrees, "Camera orbit over the run, degrees")->capture_default_str();
  auto* spinOpt = app.add_option("--spin", sweep.spinDegrees, "Object spin about Y over the run, degrees")->capture_default_str();
  app.add_option("--spin-object", sweep.spinObject, "Which object --spin turns")->capture_default_str();
  auto* lightOpt = app.add_option("--light", sweep.lightDegrees, "Light (environment) turn about Y over the run, degrees")
                       ->capture_default_str();
  app.add_option("--distance", sweep.distance, "Camera distance from the origin")->capture_default_str();
  app.add_option("--elevation", sweep.elevationDegrees, "Camera elevation, degrees")->capture_default_str();
  app.add_option("--fov", sweep.fovYDegrees, "Vertical field of view, degrees")->capture_default_str();
  pathOpt->excludes(orbitOpt)->excludes(spinOpt)->excludes(lightOpt);
  app.add_option("--clients", clients, "Sessions run at once in this process (load test)")->check(CLI::Range(1u, 256u));
  app.add_option("--in-flight", inFlight, "Poses sent ahead of their frames (1: wait for each frame)")
      ->check(CLI::Range(1u, 64u));
  app.add_option("--warmup", warmup, "Poses played first and left out of the figures (steady-state numbers)")
      ->check(CLI::Range(0u, 100000u));
  app.add_option("--duration", duration,
                 "Play for this many seconds instead of --frames poses (the path, --frames long, cycles)")
      ->check(CLI::Range(0.0, 86400.0));
  app.add_option("--timeout", timeout, "Seconds to wait for the upgrade, Welcome or any one frame")
      ->check(CLI::Range(0.1, 3600.0));
  app.add_flag("--json", json, "Print a JSON summary on stdout at the end");
  app.add_flag("--check-not-blank", checkNotBlank, "Decode every frame and fail if one is blank");
  app.add_flag("--quiet,-q", quiet, "No progress line");
  app.add_flag("--per-frame", perFrame, "A line per frame (latency, bytes) instead of the progress bar");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // A flag the client does not take: name it and the one meant, before
    // anything else CLI11 found (it checks the required url first, so
    // `haarcast-client --bogus` would otherwise say only that the url is
    // missing).
    const auto lines = haarcast::cli::unknownFlags(app, std::vector<std::string>(argv + 1, argv + argc));
    if (!lines.empty()) {
      for (const auto& line : lines) std::fprintf(stderr, "haarcast-client: error: %s\n", line.c_str());
      if (url.empty()) std::fprintf(stderr, "haarcast-client: error: the server's url (ws://HOST:PORT) is missing\n");
      std::fprintf(stderr, "`haarcast-client --help` lists the flags.\n");
      return 2;
    }
    // --help and --version exit 0; every flag error exits 2, as the checks
    // below do.
    return app.exit(e) == 0 ? 0 : 2;
  }

  SessionConfig base;
  PosePath path = PosePath::orbit(OrbitSweep{});
  try {
    base.url = parseWsUrl(url);
    const Size wh = parseSize(size);
    base.hello.set_protocol_version(haarcast::v1::PROTOCOL_VERSION_1);
    base.hello.set_width(wh.width);
    base.hello.set_height(wh.height);
    base.hello.set_encoding(parseEncoding(encoding));
    checkH264Options(base.hello.encoding(), wh, h264);
    base.hello.set_fps_cap(fpsCap);
    base.hello.set_jpeg_quality(quality);
    auto* settings = base.hello.mutable_settings();
    settings->set_method(parseMethod(method));
    if (!backend.empty()) settings->set_backend(backend == "vulkan" ? haarcast::v1::BACKEND_VULKAN : haarcast::v1::BACKEND_CPU);
    const LevelRequest levelRequest = parseLevel(level);
    settings->set_level(levelRequest.level);
    settings->set_level_mode(levelRequest.mode);
    settings->set_light_coefficients(coefficients);
    const Exposure e = parseExposure(exposure);
    settings->set_exposure_mode(e.mode);
    settings->set_exposure_stops(e.stops);
    settings->set_tone_curve(parseToneCurve(tone));
    settings->set_h264_bitrate_kbps(h264.bitrateKbps);
    settings->set_h264_keyframe_interval(h264.keyframeInterval);
    if (!scene.empty() || !materials.empty()) {
      auto* choice = base.hello.mutable_scene();
      choice->set_scene(scene);
      for (const auto& m : materials) {
        const auto [object, spec] = parseMaterial(m);
        (*choice->mutable_object_materials())[object] = spec;
      }
    }
    if (!pathFile.empty()) {
      path = PosePath::fromFile(pathFile);
      if (framesOpt->count() == 0) frames = path.naturalLength();
    } else {
      path = PosePath::orbit(sweep);
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "haarcast-client: error: %s\n", e.what());
    return 2;
  }
  base.token = token;
  base.path = &path;
  base.frames = frames;
  base.inFlight = inFlight;
  base.warmup = warmup;
  base.durationSeconds = duration;
  base.checkNotBlank = checkNotBlank;
  base.maxClipped = maxClipped;
  base.timeoutSeconds = timeout;

  boost::asio::io_context io;
  Progress progress(duration > 0.0 ? 0 : frames * clients, quiet, perFrame);
  RunSummary summary;
  summary.encoding = haarcast::wire::encodingName(base.hello.encoding());
  summary.width = base.hello.width();
  summary.height = base.hello.height();
  summary.sessions.resize(clients);
  std::vector<Session> sessions;
  sessions.reserve(clients);
  base.runStart = Clock::now();
  for (unsigned i = 0; i < clients; ++i) {
    SessionConfig config = base;
    config.hello.set_client_name("haarcast-client/" + std::to_string(i));
    if (!outDir.empty()) {
      config.outDir = clients == 1 ? outDir : (std::filesystem::path(outDir) / ("client-" + std::to_string(i))).string();
      std::error_code ec;
      std::filesystem::create_directories(config.outDir, ec);
      if (ec) {
        std::fprintf(stderr, "haarcast-client: error: cannot create --out folder %s: %s\n", config.outDir.c_str(),
                     ec.message().c_str());
        return 2;
      }
    }
    sessions.emplace_back(
        io, i, std::move(config), summary.sessions[i], [&progress](const FrameEvent& e) { progress.frame(e); },
        [&progress](const std::string& line) { progress.message(line); },
        [&progress](std::size_t client, const haarcast::v1::BuildProgress* p) { progress.build(client, p); });
  }
  // At most kPendingClients sessions between their connection and the
  // server's first answer: the server keeps a per-address pre-Hello budget
  // (--max-pending-per-address, 8 by default), and 16 upgrades at once from
  // this one address lost half of them to it. Each answer starts the next.
  constexpr std::size_t kPendingClients = 4;
  std::size_t nextToStart = 0;
  std::function<void()> startNext;
  startNext = [&] {
    if (nextToStart < sessions.size()) sessions[nextToStart++].start(startNext);
  };
  for (std::size_t k = 0; k < std::min<std::size_t>(kPendingClients, sessions.size()); ++k) startNext();
  io.run();
  progress.endLine();

  // Wall time: from the earliest first pose to the latest last frame, so that
  // connection setup and scene loading do not count against the frame rate.
  double first = 1e300, last = 0.0;
  for (const auto& s : summary.sessions) {
    if (s.frames == 0) continue;
    first = std::min(first, s.firstPoseSeconds);
    last = std::max(last, s.lastFrameSeconds);
  }
  summary.wallSeconds = last > first ? last - first : 0.0;

  if (!sessions.empty() && !quiet) {
    const auto& w = sessions.front().welcome();
    if (!w.session_id().empty()) {
      std::fprintf(stderr, "haarcast-client: server %s, device \"%s\", %ux%u %s\n", w.server_version().c_str(),
                   w.device().c_str(), w.width(), w.height(), std::string(haarcast::wire::encodingName(w.encoding())).c_str());
    }
  }
  const nlohmann::json j = summaryJson(summary);
  if (json) std::cout << j.dump(2) << std::endl;
  // No frames and a failure: say why instead of a line of zeros.
  bool explained = false;
  if (j["frames"].get<std::uint64_t>() == 0) {
    for (std::size_t i = 0; i < summary.sessions.size(); ++i) {
      if (summary.sessions[i].failure.empty()) continue;
      const std::string who = clients > 1 ? " from client " + std::to_string(i) : "";
      std::fprintf(stderr, "haarcast-client: no frames%s: %s\n", who.c_str(), summary.sessions[i].failure.c_str());
      explained = true;
    }
  }
  if (!explained && (!quiet || !json)) {
    std::fprintf(stderr, "haarcast-client: %llu frames, %.1f fps, latency p50 %.1f ms p99 %.1f ms, %.0f bytes/frame, %llu dropped, %llu errors\n",
                 static_cast<unsigned long long>(j["frames"].get<std::uint64_t>()), j["fps"].get<double>(),
                 j["latency_ms_p50"].get<double>(), j["latency_ms_p99"].get<double>(), j["bytes_per_frame"].get<double>(),
                 static_cast<unsigned long long>(j["dropped"].get<std::uint64_t>()),
                 static_cast<unsigned long long>(j["errors"].get<std::uint64_t>()));
  }

  // Exit 1 when anything went wrong: a failed session, a server Error, a
  // blank frame, or a frame that never came. An H.264 frame that did not
  // decode is recovered from (a keyframe is asked for), but when frames are
  // checked it is one that was not: that fails the run too.
  bool ok = j["errors"].get<std::uint64_t>() == 0 && j["blank_frames"].get<std::uint64_t>() == 0 &&
            j["clipped_frames"].get<std::uint64_t>() == 0;
  if ((checkNotBlank || maxClipped >= 0.0) && j["undecoded_frames"].get<std::uint64_t>() != 0) ok = false;
  for (const auto& s : summary.sessions) ok = ok && s.failure.empty();
  const std::uint64_t answered = j["frames"].get<std::uint64_t>() + j["dropped"].get<std::uint64_t>();
  if (ok && duration <= 0.0 && answered != frames * clients) ok = false;
  if (ok && duration > 0.0 && j["frames"].get<std::uint64_t>() == 0) ok = false;
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "haarcast-client: error: %s\n", e.what());
    return 1;
  }
}
