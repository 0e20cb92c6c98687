// `haarcast serve`: the render service on one port (server/net). This file
// only turns flags into a catalogue of scenes and materials, a renderer
// builder (the backend factory) and server options.
#include "serve_command.h"
#include "list_flags.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

#include "haarcast/backends/backends.h"
#include "haarcast/core/check.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/shared_smooth.h"
#include "haarcast/net/host_check.h"
#include "haarcast/net/protocol.h"
#include "haarcast/net/left_behind.h"
#include "haarcast/net/server.h"
#include "haarcast/render/build_plan.h"
#include "haarcast/render/object_levels.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"
#include "haarcast/wire/encoding_name.h"
#include "app_paths.h"
#include "progress.h"
#include "scene_flags.h"
#include "serve_catalog.h"

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;

struct ServeArgs {
  net::ServerOptions server;
  std::string token;
  int port = 8080;  // checked, then narrowed into server.port
  int grpcPort = 0;  // 0: no gRPC listener
  std::string antialias = "auto";
  float sumTolerance = shared::kDefaultSumTolerance;  // fused: RenderOptions::sumTolerance
  float smoothSum = shared::kDefaultSmoothSumTolerance;  // fused: RenderOptions::smoothSumTolerance
  std::string backend{render::kCpuBackend}, method = "fused", encoding = "jpeg";
  std::vector<std::string> backends;  // enabled for clients; empty: just --backend
  std::string level = "auto";  // render::parseLevelChoice; auto: its cap at most --max-level
  std::size_t lightCoefficients = 256;
  std::vector<std::string> sceneFiles;
  std::string materialsDir, dataDir, webRoot, protoFile, cacheDir, vulkanDevice;
  std::string rays = "auto";
  render::SceneLimits sceneLimits;
  bool vulkanValidation = false, quiet = false;
  std::size_t framesInFlight = 0;
  std::uint32_t vulkanQueues = 1;
  unsigned renderThreads = 0;
  long long serverPixelBudget = -1;  // -1: 2 × --max-session-pixels
};

using SceneSource = ServedScene;

int run(ServeArgs& a) {
  // Flags → the catalogue: scenes by name, offered materials, backends.
  std::vector<SceneSource> scenes;
  scenes.push_back({"default", render::defaultScene()});
  for (const auto& file : a.sceneFiles) {
    std::string name = fs::path(file).stem().string();
    for (const auto& s : scenes) {
      if (s.name == name) throw std::invalid_argument("--scene " + file + ": a scene named \"" + name + "\" is already served");
    }
    scenes.push_back({name, render::loadScene(file, a.sceneLimits)});
  }
  // The names clients may choose; the files behind them stay here (servedScene).
  const auto served = std::make_shared<const ServeCatalog>(buildServeCatalog(scenes, a.materialsDir, a.dataDir, a.sceneLimits));
  net::Catalog catalog = served->catalog;
  if (!a.dataDir.empty() && !a.quiet) {
    std::string line = "[serve] --data offers " + std::to_string(catalog.probes.size()) + " probes, " +
                       std::to_string(catalog.meshes.size()) + " meshes (up guessed:";
    for (const auto& m : catalog.meshes) line += " " + m.name + " " + std::string(net::upAxisName(m.guessedUp));
    std::fprintf(stderr, "%s)\n", line.c_str());
  }
  // Backends: those built into this binary; clients may use only the ones
  // the operator enabled (--backends, else just --backend).
  const auto enable = [&](const std::string& flag, const std::string& name) {
    backends::checkBuilt(name, flag);
    const auto backend = net::parseBackend(name);
    HC_CHECK_EQ(backend.has_value(), true);  // every built backend has a wire name
    if (!catalog.offersBackend(*backend)) catalog.backends.push_back(*backend);
    return *backend;
  };
  const net::Backend defaultBackend = enable("--backend", a.backend);
  for (const auto& b : a.backends) enable("--backends", b);

  const auto method = parseRotationMethod(a.method);
  if (!method) throw std::invalid_argument("--method must be one of " + pixelMethodNames() + " (got \"" + a.method + "\")");
  auto& d = a.server.defaults;
  d.method = *method;
  const auto level = render::parseLevelChoice(a.level);
  if (!level) throw std::invalid_argument("--level must be " + render::levelChoiceHelp() + " (got \"" + a.level + "\")");
  // The default cap follows a lower --max-level; an explicit one must fit it (below).
  d.level = a.level == "auto" ? std::min(level->level, a.server.limits.maxLevel) : level->level;
  d.automaticLevel = level->automatic;
  d.lightCoefficients = a.lightCoefficients;
  d.backend = defaultBackend;
  // The names are the wire's (wire::encodingName), so a new encoding in the
  // .proto is a flag value here once the server can send it.
  const std::optional<v1::Encoding> wireEncoding = wire::encodingFromName(a.encoding);
  const std::optional<net::FrameEncoding> encoding = wireEncoding ? net::fromWire(*wireEncoding) : std::nullopt;
  if (!encoding) throw std::invalid_argument("--encoding must be jpeg, png, raw, exr or h264 (got \"" + a.encoding + "\")");
  d.encoding = *encoding;
  a.server.port = static_cast<std::uint16_t>(a.port);
  if (a.grpcPort != 0) {
    if (a.grpcPort == a.port) throw std::invalid_argument("--grpc-port must differ from --port (both " + std::to_string(a.port) + ")");
    a.server.grpcPort = static_cast<std::uint16_t>(a.grpcPort);
  }
  auto& limits = a.server.limits;
  if (limits.maxLevel < render::kMinRenderLevel || limits.maxLevel > render::kMaxRenderLevel) {
    throw std::invalid_argument("--max-level " + std::to_string(limits.maxLevel) + " is outside " +
                                std::to_string(render::kMinRenderLevel) + ".." + std::to_string(render::kMaxRenderLevel));
  }
  if (d.level < limits.minLevel || d.level > limits.maxLevel) {
    throw std::invalid_argument("--level " + a.level + " is outside " + std::to_string(limits.minLevel) + ".." +
                                std::to_string(limits.maxLevel) + " (see --max-level)");
  }
  const auto& admission = a.server.admission;
  for (const auto& [flag, value] : {std::pair{"--max-sessions", admission.sessions},
                                    {"--max-sessions-per-address", admission.sessionsPerAddress},
                                    {"--max-connections-per-address", admission.connectionsPerAddress},
                                    {"--max-pending", admission.pending},
                                    {"--max-pending-per-address", admission.pendingPerAddress}}) {
    if (value < 1) throw std::invalid_argument(std::string(flag) + " must be at least 1 (got " + std::to_string(value) + ")");
  }
  if (admission.sessionReserve < -1) {
    throw std::invalid_argument("--session-reserve must be -1 (automatic: min(8, --max-sessions / 4)) or at least 0 (got " +
                                std::to_string(admission.sessionReserve) + ")");
  }
  if (!(limits.maxFps > 0)) throw std::invalid_argument("--max-fps must be positive");
  limits.defaultFps = std::min(limits.defaultFps, limits.maxFps);

  auto& render = a.server.render;
  if (!(render.frameDeadlineSeconds >= 0.0)) {
    throw std::invalid_argument("--frame-deadline must be at least 0 seconds (0: none; got " +
                                std::to_string(render.frameDeadlineSeconds) + ")");
  }
  for (const auto& [flag, value] : {std::pair{"--render-workers", static_cast<std::size_t>(std::max(0, render.workers))},
                                    {"--max-session-pixels", render.maxSessionPixels},
                                    {"--max-queued-builds", render.maxQueuedBuilds}}) {
    if (value < 1) throw std::invalid_argument(std::string(flag) + " must be at least 1 (got " + std::to_string(value) + ")");
  }
  // The protocol refuses a Hello over the per-session budget up front.
  limits.maxPixels = render.maxSessionPixels;
  // Unset (the sentinel): two of the largest frames a session may ask for.
  if (a.serverPixelBudget < 0) {
    render.serverPixelBudget = 2 * render.maxSessionPixels;
  } else {
    render.serverPixelBudget = static_cast<std::size_t>(a.serverPixelBudget);
  }

  // The token: the flag, else the environment (keeps it out of `ps`).
  a.server.token = !a.token.empty() ? a.token : (std::getenv("HAARCAST_TOKEN") ? std::getenv("HAARCAST_TOKEN") : "");
  a.server.webRoot = !a.webRoot.empty() ? fs::path(a.webRoot)
                                        : findShipped("client/web", {"../share/haarcast/web", "../client/web", "web"});
  if (!a.webRoot.empty()) {
    std::error_code ec;
    if (!fs::is_regular_file(a.server.webRoot / "index.html", ec)) {
      throw std::invalid_argument("--web-root " + a.webRoot + ": " +
                                  (fs::is_directory(a.server.webRoot, ec) ? "has no index.html" : "no such folder") +
                                  " (it takes the browser client's folder, client/web in the source tree)");
    }
  }
  if (!a.protoFile.empty() && !fs::is_regular_file(fs::path(a.protoFile))) {
    throw std::invalid_argument("--proto-file " + a.protoFile + ": no such file");
  }
  a.server.protoFile = !a.protoFile.empty()
                           ? fs::path(a.protoFile)
                           : findShipped("proto/haarcast.proto", {"../share/haarcast/haarcast.proto", "haarcast.proto"});
  a.server.log = !a.quiet;
  a.server.handleSignals = true;

  // The renderer builder: a config's scene with its materials, through the
  // backend factory. Runs on the render service's builder thread.
  render::RenderOptions base;
  base.cacheDir = cacheDirFromFlag(a.cacheDir);
  base.sceneLimits = a.sceneLimits;
  base.threads = a.renderThreads;
  base.sumTolerance = a.sumTolerance;
  base.smoothSumTolerance = a.smoothSum;
  const backends::DeviceOptions vulkanOptions{a.vulkanDevice, a.vulkanValidation, a.framesInFlight,
                                              parseRayModeFlag(a.rays), a.vulkanQueues};
  auto sharedScenes = std::make_shared<std::vector<SceneSource>>(std::move(scenes));
  const bool quiet = a.quiet;
  const std::string antialias = a.antialias;
  antialiasFor(antialias, a.backend);  // a bad flag fails at start, not in a session
  // A session's config → the scene with its materials and the render
  // options: what the builder builds and what the planner plans.
  struct Resolved {
    render::Scene scene;
    render::RenderOptions options;
    std::string backend;
  };
  auto resolve = [sharedScenes, served, base, antialias](const net::SessionConfig& c) {
    Resolved r{servedScene(*sharedScenes, *served, c), base, std::string(net::backendName(c.backend))};
    render::RenderOptions& options = r.options;
    options.method = c.method;
    render::applyLevelChoice(options, {c.level, c.automaticLevel});
    options.lightCoefficients = c.lightCoefficients;
    options.antialias = antialiasFor(antialias, r.backend);
    return r;
  };
  // The planner and then the builder take the same config on the builder
  // thread: the planner's resolved scene (its probe and MERL files read) is
  // handed to the builder instead of being read again.
  struct Handoff {
    std::mutex mutex;
    std::string key;
    std::shared_ptr<const Resolved> resolved;
  };
  auto handoff = std::make_shared<Handoff>();
  a.server.render.planner = [resolve, handoff, quiet](const net::SessionConfig& c) {
    auto resolved = std::make_shared<const Resolved>(resolve(c));
    {
      std::lock_guard lock(handoff->mutex);
      handoff->key = c.rendererKey();
      handoff->resolved = resolved;
    }
    const Resolved& r = *resolved;
    render::BuildPlan plan = render::planBuild(r.scene, r.options, r.backend);
    if (!quiet) {
      // The plan beside the stages' own lines: how the estimate was made.
      std::string line = "[serve] build plan (estimated work, s on the reference machine):";
      for (const render::PlannedStage& s : plan.stages) {
        char work[32];
        std::snprintf(work, sizeof work, " %.3g", s.work);
        line += " " + s.name + work + ";";
      }
      std::fprintf(stderr, "%s\n", line.c_str());
    }
    return plan;
  };
  // Abandonable: once nobody waits for the build (its sessions closed, or
  // the server stops) the next progress step throws, so a SIGTERM during a
  // build of seconds still exits at once. Every progress step also goes to
  // the waiting clients (`toClients`: BuildProgress messages, throttled by
  // the render service) besides the log.
  net::AbandonableRendererBuilder builder = [resolve, handoff, vulkanOptions, quiet](
                                                const net::SessionConfig& c, const std::function<bool()>& abandoned,
                                                const render::RenderProgress& toClients) {
    std::shared_ptr<const Resolved> planned;
    {
      std::lock_guard lock(handoff->mutex);
      if (handoff->resolved && handoff->key == c.rendererKey()) planned = std::move(handoff->resolved);
      handoff->resolved.reset();  // not kept past its build
    }
    if (!planned) planned = std::make_shared<const Resolved>(resolve(c));  // no plan was made for it
    const Resolved& r = *planned;
    const render::Scene& scene = r.scene;
    const render::RenderOptions& options = r.options;
    const std::string& backend = r.backend;
    if (!quiet) std::fprintf(stderr, "[serve] preparing renderer %s\n", c.rendererKey().c_str());
    auto prepared = std::make_shared<net::PreparedRenderer>();
    // Slice tables and visibility: lines, not a redrawn one (sessions log in between).
    StderrProgress progress("[serve] ", false);
    const StageProgress shown = quiet ? StageProgress{} : progress.callback();
    const render::RenderProgress stages = [&](const std::string& stage, std::size_t done, std::size_t total) {
      if (abandoned()) throw std::runtime_error("renderer build abandoned: nobody waits for it");
      if (shown) shown(stage, done, total);
      if (toClients) toClients(stage, done, total);
    };
    prepared->renderer = backends::makeRenderer(backend, scene, options, vulkanOptions, stages);
    if (backend == render::kVulkanBackend) {
      // The build's last stage: a tiny frame. A Vulkan driver may compile
      // its shaders at their first dispatch (Mesa's lavapipe: up to ~45 s),
      // which then shows as build progress instead of a first frame that
      // runs into the frame deadline. It stops with the build when nobody
      // waits for it any more.
      stages("warm-up", 0, 1);
      render::FrameRequest warmUp;
      warmUp.width = warmUp.height = 16;
      warmUp.camera = scene.camera;
      warmUp.linearImage = false;
      warmUp.cancelled = abandoned;
      prepared->renderer->render(warmUp);
      stages("warm-up", 1, 1);
    }
    if (!quiet) {
      // framesInFlight() 0: any number (the CPU backend, bounded by the workers).
      const std::size_t k = prepared->renderer->framesInFlight();
      const std::string inFlight = k == 0 ? "frames in flight up to the workers"
                                          : std::to_string(k) + (k == 1 ? " frame" : " frames") + " in flight";
      std::fprintf(stderr, "[serve] renderer ready: %s on %s, rays %s, %s\n", prepared->renderer->backend().c_str(),
                   prepared->renderer->deviceName().c_str(), prepared->renderer->rays().c_str(), inFlight.c_str());
    }
    return prepared;
  };

  net::Server server(a.server, std::move(catalog), std::move(builder));
  // Said even with --quiet: an open port without a token is the operator's to know.
  if (const auto warning = net::exposureWarning(a.server); warning && a.quiet) std::fprintf(stderr, "%s\n", warning->c_str());
  // The line scripts and clients wait for: the bound port, flushed.
  std::printf("listening on http://127.0.0.1:%u/\n", static_cast<unsigned>(server.port()));
  std::fflush(stdout);
  if (!a.quiet) {
    std::fprintf(stderr, "[serve] browser client: http://127.0.0.1:%u/%s (web root %s)\n",
                 static_cast<unsigned>(server.port()), a.server.token.empty() ? "" : "?token=…",
                 a.server.webRoot.empty() ? "not found" : a.server.webRoot.c_str());
  }
  server.run();  // until SIGINT/SIGTERM, then drains
  // A render or build thread stuck inside a library call (logged above,
  // with its stage) is not waited for, and neither are destructors that
  // could wait on it or pull the library from under it (the renderer's,
  // Embree's and the driver's at exit): leave now, the log flushed, with
  // the status of a clean stop (net/left_behind.h).
  net::exitNowIfThreadsLeftBehind(0);
  return 0;
}

}  // namespace

std::function<int()> addServeCommand(CLI::App& app) {
  auto a = std::make_shared<ServeArgs>();
  auto* c = app.add_subcommand("serve", "Serve frames over WebSocket to CLI and browser clients (HTTP on the same port)");
  auto& o = a->server;
  c->add_option("--port", a->port, "TCP port 0..65535 (0 = any free one; the bound one is printed)")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  c->add_option("--grpc-port", a->grpcPort,
                 "TCP port of the gRPC listener (haarcast.v1.Render, grpc.health.v1.Health, reflection) on the "
                 "--bind address; 0 = none")
      ->capture_default_str()
      ->check(CLI::Range(0, 65535));
  c->add_option("--bind", o.bindAddress,
                 "Address to listen on (0.0.0.0: every interface; then set a token, a warning says so)")
      ->capture_default_str();
  c->add_option("--allow-origin", o.allowOrigins,
                 "A web origin (https://app.example.com) whose pages may open sessions, besides this server's own "
                 "(repeatable)");
  c->add_option("--allow-host", o.allowHosts,
                 "A host name clients reach this server by (the Host header), besides IP literals and localhost; "
                 "others get 421 (DNS rebinding). Repeatable or comma-separated; '*' allows any")
      ->delimiter(',')
      ->check([](const std::string& value) -> std::string {
        if (value == "*" || net::hostName(value)) return "";
        return "--allow-host " + value + " is not a host name (a name like render.example.com, optionally :PORT)";
      });
  c->add_option("--token", a->token, "Required token (?token=T or Authorization: Bearer T); default $HAARCAST_TOKEN");
  c->add_option("--backend", a->backend, "Default backend: " + backends::availableText())->capture_default_str();
  c->add_option("--backends", a->backends, "Backends clients may choose (default: only --backend)")->delimiter(',');
  c->add_option("--sum-tolerance", a->sumTolerance,
                sumToleranceHelp())
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--smooth-sum", a->smoothSum, smoothSumHelp())
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  c->add_option("--antialias", a->antialias, "auto|on|off: edge pixels as the mean of 4 sub-samples (auto: on)")
      ->capture_default_str();
  c->add_option("--level", a->level,
                "Default map level n (M = 2^n), within the session limits (--max-level): " + render::levelChoiceHelp() +
                    "; auto's cap is at most --max-level")
      ->capture_default_str();
  c->add_option("--method", a->method, "Default per-pixel method: " + pixelMethodNames())->capture_default_str();
  c->add_option("--light-coeffs", a->lightCoefficients, "Default light coefficients kept (k)")->capture_default_str();
  c->add_option("--encoding", a->encoding, "Default encoding: jpeg|png|raw|exr|h264")->capture_default_str();
  c->add_option("--scene", a->sceneFiles, "Scene files to offer besides the built-in \"default\" (named by file stem)");
  c->add_option("--materials-dir", a->materialsDir, "Offer the MERL .binary files of this folder (as merl:NAME)");
  c->add_option("--data", a->dataDir,
                "Offer the files of this folder by name: probes/ (EXR, HDR, PFM) as environments, meshes/ (PLY, OBJ) "
                "as mesh scenes (the mesh on a ground), brdfs/ (MERL .binary) as merl:NAME; each file is read at start");
  c->add_option("--web-root", a->webRoot, "The browser client's files (default: the source tree's client/web)");
  c->add_option("--proto-file", a->protoFile, "Served at /haarcast.proto (default: the source tree's)");
  addSceneLimitFlags(*c, a->sceneLimits);
  c->add_option("--cache-dir", a->cacheDir, "Slice-table and visibility cache (default $XDG_CACHE_HOME/haarcast; 'none')");
  c->add_option("--max-sessions", o.admission.sessions, "Concurrent sessions (counted from a valid Hello)")
      ->capture_default_str();
  c->add_option("--max-sessions-per-address", o.admission.sessionsPerAddress, "Concurrent sessions per client address")
      ->capture_default_str();
  c->add_option("--max-connections-per-address", o.admission.connectionsPerAddress,
                "Open TCP connections per client address (HTTP and WebSocket)")
      ->capture_default_str();
  c->add_option("--max-pending", o.admission.pending, "WebSocket connections waiting for their Hello, server-wide")
      ->capture_default_str();
  c->add_option("--max-pending-per-address", o.admission.pendingPerAddress,
                "WebSocket connections waiting for their Hello, per client address")
      ->capture_default_str();
  c->add_option("--session-reserve", o.admission.sessionReserve,
                "Session slots kept for client addresses that hold none, so that a few addresses cannot fill "
                "--max-sessions (-1: min(8, --max-sessions / 4); 0 behind a proxy whose few addresses carry every client)")
      ->capture_default_str();
  c->add_option("--max-width", o.limits.maxWidth, "Largest frame width")->capture_default_str();
  c->add_option("--max-height", o.limits.maxHeight, "Largest frame height")->capture_default_str();
  c->add_option("--max-fps", o.limits.maxFps, "Largest frame rate per session")->capture_default_str();
  c->add_option("--max-level", o.limits.maxLevel,
                 "Largest map level a client may ask for (" + std::to_string(render::kMinRenderLevel) + ".." +
                     std::to_string(render::kMaxRenderLevel) + ")")
      ->capture_default_str();
  c->add_option("--max-message-bytes", o.limits.maxMessageBytes, "Largest client message")->capture_default_str();
  c->add_option("--handshake-timeout", o.handshakeSeconds, "Seconds for the HTTP request and the Hello")->capture_default_str();
  c->add_option("--idle-timeout", o.idleSeconds, "Seconds without a client message before closing")->capture_default_str();
  c->add_option("--io-threads", o.ioThreads, "Network threads")->capture_default_str();
  c->add_option("--render-threads", a->renderThreads, "CPU backend threads (0 = all cores)")->capture_default_str();
  c->add_option("--max-renderers", o.render.maxRenderers, "Prepared renderers kept (LRU)")->capture_default_str();
  c->add_option("--render-workers", o.render.workers,
                "Frames of different sessions rendering at once (a Vulkan renderer: one at a time)")
      ->capture_default_str();
  c->add_option("--max-session-pixels", o.render.maxSessionPixels,
                "Largest frame (width × height) one session may ask for; a larger one is an Error")
      ->capture_default_str();
  c->add_option("--server-pixel-budget", a->serverPixelBudget,
                "Pixels rendering at once across the server; a frame waits for its share, /readyz is 503 while one "
                "waits (default 2 × --max-session-pixels; 0 = none)");
  c->add_option("--frame-deadline", o.render.frameDeadlineSeconds,
                "Seconds a frame may render; a longer one is abandoned: its client gets an error naming the stage it "
                "was stuck in, its device turns unhealthy (its frames fail at once, /readyz 503 when it is the "
                "default backend's) until the frame returns. Far above any real frame; 0 = none")
      ->capture_default_str();
  c->add_option("--max-queued-builds", o.render.maxQueuedBuilds,
                "Renderer builds waiting across the server; one more is refused with Error OVERLOADED")
      ->capture_default_str();
  c->add_option("--vulkan-device", a->vulkanDevice, "Vulkan device name substring");
  c->add_flag("--vulkan-validation", a->vulkanValidation, "Enable the Vulkan validation layers");
  c->add_option("--rays", a->rays, rayModeHelp())->capture_default_str();
  c->add_option("--vulkan-queues", a->vulkanQueues,
                "The most queues the Vulkan device is opened with, each frame slot lent the least-lent: frames on "
                "different queues run side by side, where on one queue each barrier waits for the frames submitted "
                "before it (0: every queue its family offers, at most 16). One by default: on the H200 a 1280x720 frame "
                "fills the device and frames side by side made fewer frames in all (docs/gpu.md)")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  c->add_option("--frames-in-flight", a->framesInFlight,
                "Frames a Vulkan renderer may render at once, each with its own device buffers (the scene uploaded once "
                "per frame in flight): while one frame's host stages run, another's passes run on the device. "
                "0 = 1 on a CPU device (lavapipe), 2 on a GPU")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  c->add_flag("--quiet", a->quiet, "No per-session log lines on stderr");
  return [c, a]() { return c->parsed() ? run(*a) : -1; };
}

}  // namespace haarcast::app
