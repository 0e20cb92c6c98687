// `haarcast bench-frame`: per-pass and whole-frame times of each backend
// against resolution and level, in one run, so that CPU/Vulkan ratios come
// from the same machine state; plus the coefficient bytes each frame reads
// per method, and (with both backends) how closely the two images agree.
#include "bench_frame_command.h"

#include <algorithm>
#include <atomic>
#include <barrier>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "haarcast/backends/backends.h"
#include "haarcast/core/check.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/shared_smooth.h"
#include "list_flags.h"
#include "progress.h"
#include "haarcast/render/object_levels.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"

namespace haarcast::app {
namespace {

// How fused sums a pixel: RenderOptions::sumTolerance and smoothSumTolerance.
struct SumChoice {
  float cells = 0.0f;
  float smooth = 0.0f;
};

// The bench's "sum" column.
std::string sumName(RotationMethod method, const SumChoice& sum) {
  if (method != RotationMethod::Fused) return "—";
  char text[64];
  if (sum.cells > 0.0f) std::snprintf(text, sizeof text, "cells τ %g", static_cast<double>(sum.cells));
  else std::snprintf(text, sizeof text, "every direction");
  std::string out = text;
  if (sum.smooth > 0.0f) {
    std::snprintf(text, sizeof text, ", smooth ε %g", static_cast<double>(sum.smooth));
    out += text;
  }
  return out;
}

std::string defaultTolerance(float value) {
  char text[16];
  std::snprintf(text, sizeof text, "%g", static_cast<double>(value));
  return text;
}

struct BenchArgs {
  std::string backend = "both";
  std::string sizes = "128";
  std::string levels = "4";
  std::string methods{methodName(kDefaultPixelMethod)};
  std::string slices = "blend";  // fused: blend | nearest
  std::string antialias = "off";  // on: the cost of the edge sub-samples, on either backend
  std::string scene;  // scene file; empty = the built-in default
  std::string device;
  std::string rays = "auto";
  bool objectSky = true;  // fused: objects hide sky from each other (RenderOptions::objectSky)
  // fused: RenderOptions::sumTolerance, one run each (default: render's and serve's)
  std::string sumTolerances = defaultTolerance(shared::kDefaultSumTolerance);
  // fused: RenderOptions::smoothSumTolerance, one run each with each of the above
  std::string smoothSums = defaultTolerance(shared::kDefaultSmoothSumTolerance);
  std::string cacheDir;
  // Vulkan: frames in flight to measure, comma-separated (empty: none), each
  // as that many threads rendering at once on one renderer of as many slots.
  std::string inFlight;
  std::uint32_t queues = 1;  // Vulkan: the most device queues (0: all its family offers)
  std::uint32_t fusedLocalSize = 0;  // Vulkan: fused's workgroup size (0: the device's default)
  int frames = 3;
  int warmup = 1;
  bool json = false;
};

// Mean of each stage and of the frame over the timed frames.
struct Measured {
  std::vector<std::pair<std::string, double>> stages;
  std::map<std::string, double> parts;  // render::Frame::parts, the mean of each
  double frameSeconds = 0.0;
  std::size_t coefficientBytes = 0;
  std::size_t covered = 0;
  // `fused`: the map directions its pass visits per object sample, the mean
  // and the most for one (render::Frame::passDirections).
  double directionsMean = 0.0;
  std::size_t directionsMax = 0;
  render::Frame first;  // an untimed frame with its linear image, for the comparison
};

// The timed frames are the service's: RGBA8 only (FrameRequest::linearImage
// false), so the linear image's readback is not in the figures; one
// untimed frame first brings the linear image and the object mask.
Measured measure(render::Renderer& r, const render::FrameRequest& request, int frames, int warmup) {
  // Warm-up: first-use allocation and shader variants are not the steady state.
  for (int i = 0; i < warmup; ++i) r.render(request);
  Measured m;
  render::FrameRequest linear = request;
  linear.linearImage = true;
  m.first = r.render(linear);
  render::FrameRequest timed = request;
  timed.linearImage = false;
  for (int i = 0; i < frames; ++i) {
    render::Frame f = r.render(timed);
    if (m.stages.empty()) {
      for (const auto& s : f.stages) m.stages.emplace_back(s.name, 0.0);
    }
    for (std::size_t k = 0; k < f.stages.size() && k < m.stages.size(); ++k) m.stages[k].second += f.stages[k].seconds / frames;
    for (const auto& part : f.parts) m.parts[part.name] += part.seconds / frames;
    m.frameSeconds += f.seconds / frames;
    m.coefficientBytes = f.coefficientBytes;
    m.directionsMean = f.passSamples ? static_cast<double>(f.passDirections) / static_cast<double>(f.passSamples) : 0.0;
    m.directionsMax = f.passDirectionsMax;
  }
  for (std::uint8_t b : m.first.objectMask) m.covered += b;
  return m;
}

// Frames per second in all with `k` frames in flight: k threads, each
// rendering one warm-up frame (its slot's first) and then `frames` timed
// frames, all started together; the wall time of the timed frames.
double measureInFlight(render::Renderer& r, const render::FrameRequest& request, int frames, std::size_t k) {
  render::FrameRequest timed = request;
  timed.linearImage = false;
  std::barrier ready(static_cast<std::ptrdiff_t>(k) + 1), done(static_cast<std::ptrdiff_t>(k) + 1);
  std::vector<std::jthread> threads;
  std::atomic<bool> failed{false};
  for (std::size_t t = 0; t < k; ++t) {
    threads.emplace_back([&] {
      try {
        r.render(timed);
      } catch (...) {
        failed = true;
      }
      ready.arrive_and_wait();
      try {
        for (int i = 0; i < frames && !failed; ++i) r.render(timed);
      } catch (...) {
        failed = true;
      }
      done.arrive_and_wait();
    });
  }
  ready.arrive_and_wait();
  const auto t0 = std::chrono::steady_clock::now();
  done.arrive_and_wait();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (failed) throw std::runtime_error("--in-flight " + std::to_string(k) + ": a frame failed");
  return wall > 0.0 ? static_cast<double>(k) * frames / wall : 0.0;
}

// PSNR over identically covered pixels (peak = the reference's object
// maximum), and the coverage mismatches, as the GPU tests compute them.
std::pair<double, std::size_t> agreement(const render::Frame& reference, const render::Frame& test) {
  double peak = 0.0, sum = 0.0;
  std::size_t compared = 0, mismatched = 0;
  for (std::size_t p = 0; p < reference.objectMask.size(); ++p) {
    if (reference.objectMask[p] != test.objectMask[p]) {
      ++mismatched;
      continue;
    }
    ++compared;
    for (std::size_t c = 0; c < 3; ++c) {
      const double a = reference.image.rgb[3 * p + c], b = test.image.rgb[3 * p + c];
      if (reference.objectMask[p]) peak = std::max(peak, a);
      sum += (a - b) * (a - b);
    }
  }
  const double mse = compared ? sum / (3.0 * static_cast<double>(compared)) : 0.0;
  return {mse > 0.0 ? 10.0 * std::log10(peak * peak / mse) : std::numeric_limits<double>::infinity(), mismatched};
}

int run(const BenchArgs& a) {
  if (a.backend != "both") backends::checkBuilt(a.backend, "--backend");
  else backends::checkBuilt(render::kVulkanBackend, "--backend both: backend");
  if (a.frames < 1 || a.frames > 1000) throw std::invalid_argument("--frames must be in 1..1000");
  if (a.warmup < 0 || a.warmup > 100) throw std::invalid_argument("--warmup must be in 0..100");
  const std::vector<std::pair<int, int>> sizes = parseSizeList(a.sizes, "--sizes");
  std::vector<std::size_t> inFlight;
  if (!a.inFlight.empty()) {
    for (const std::string& item : splitList(a.inFlight, "--in-flight")) {
      const int k = std::atoi(item.c_str());
      if (k < 1 || k > 16 || std::to_string(k) != item) {
        throw std::invalid_argument("--in-flight: \"" + item + "\" is not a count of frames in 1..16");
      }
      inFlight.push_back(static_cast<std::size_t>(k));
    }
    if (a.backend == std::string(render::kCpuBackend)) {
      throw std::invalid_argument("--in-flight measures the Vulkan backend's frames in flight: give --backend vulkan or both");
    }
  }
  const std::size_t slots = inFlight.empty() ? 0 : *std::max_element(inFlight.begin(), inFlight.end());
  const render::RayMode rays = parseRayModeFlag(a.rays);
  if (a.slices != "blend" && a.slices != "nearest") {
    throw std::invalid_argument("--slices must be blend or nearest (got \"" + a.slices + "\")");
  }
  std::vector<render::LevelChoice> levels;
  for (const std::string& item : splitList(a.levels, "--levels")) {
    const auto choice = render::parseLevelChoice(item);
    if (!choice) throw std::invalid_argument("--levels: \"" + item + "\" is not " + render::levelChoiceHelp());
    levels.push_back(*choice);
  }
  const std::vector<RotationMethod> methods = parseMethodList(a.methods, "--method", true);
  std::vector<SumChoice> sums;
  for (const float cells : parseToleranceList(a.sumTolerances, "--sum-tolerance"))
    for (const float smooth : parseToleranceList(a.smoothSums, "--smooth-sum")) sums.push_back({cells, smooth});
  const std::string cpuName(render::kCpuBackend), vulkanName(render::kVulkanBackend);
  const bool cpu = a.backend != vulkanName, vulkan = a.backend != cpuName;
  if (a.antialias != "on" && a.antialias != "off") {
    throw std::invalid_argument("--antialias must be on or off (got \"" + a.antialias + "\")");
  }
  const bool antialias = a.antialias == "on";
  const render::Scene scene = a.scene.empty() ? render::defaultScene() : render::loadScene(a.scene);

  nlohmann::json out;
  out["scene"] = a.scene.empty() ? "default" : a.scene;
  out["frames"] = a.frames;
  out["warmup"] = a.warmup;
  out["runs"] = nlohmann::json::array();
  if (vulkan) {
    // The process's one Vulkan engine, made here without validation:
    // timing, and the layers would dominate (below too).
    nlohmann::json devices = nlohmann::json::array();
    for (const auto& d : backends::vulkanDevices(false)) {
      devices.push_back({{"index", d.index}, {"name", d.name}, {"type", d.type}, {"api", d.api}, {"rejected", d.rejected}});
    }
    out["vulkan_devices"] = devices;
  }
  // The table goes out a row at a time, as each is measured (a run of
  // every method and level takes many minutes); with --json only the JSON,
  // at the end. stderr says how many rows are done and left either way.
  auto line = [&](const std::string& s) {
    if (a.json) return;
    std::fputs((s + "\n").c_str(), stdout);
    std::fflush(stdout);
  };
  // "fused / splitsum": the one pass of either, in place of rotation and triple product.
  // "directions": what fused's pass visits per object sample, mean / most.
  line("| level | method | sum | size | backend | light | gbuffer | rotation-input | shadow-rays | rotation | triple-product | fused / splitsum | tonemap | frame (s) | fps | coeff. bytes/frame | directions / sample (mean, max) | vs cpu |");
  line("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
  std::size_t runs = 0;  // per level: one per method, fused one per pair of tolerances
  for (const RotationMethod method : methods) runs += method == RotationMethod::Fused ? sums.size() : 1;
  const std::size_t rows = levels.size() * runs * sizes.size() * ((cpu ? 1 : 0) + (vulkan ? 1 : 0));
  std::size_t rowsDone = 0;
  const auto started = std::chrono::steady_clock::now();
  StderrProgress progress("[bench-frame] ");
  auto rowDone = [&](const std::string& what, double fps) {
    ++rowsDone;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    char text[256];
    std::snprintf(text, sizeof text, "row %zu of %zu (%s: %.2f fps); %zu left, %s so far", rowsDone, rows, what.c_str(),
                  fps, rows - rowsDone, formatDuration(elapsed).c_str());
    progress.message(text);
  };

  for (const render::LevelChoice& choice : levels) {
    const std::string level = choice.name();
    for (const RotationMethod method : methods) {
      // fused: one run per pair of tolerances; the other methods sum no cells.
      for (const SumChoice& choiceOfSum : method == RotationMethod::Fused ? sums : std::vector<SumChoice>{SumChoice{}}) {
        const std::string sum = sumName(method, choiceOfSum);
        render::RenderOptions options;
        options.method = method;
        render::applyLevelChoice(options, choice);
        options.interpolateSlices = a.slices == "blend";
        options.antialias = antialias;
        options.objectSky = a.objectSky;
        options.sumTolerance = choiceOfSum.cells;
        options.smoothSumTolerance = choiceOfSum.smooth;
        options.cacheDir = a.cacheDir == "none" ? "" : a.cacheDir;
        progress.message("level " + level + ", " + std::string(methodName(method)) + (method == RotationMethod::Fused ? ", " + sum : "") +
                         ": preparing");
        std::unique_ptr<render::Renderer> cpuRenderer, gpuRenderer;
        // Slice tables, visibility, rotators: the same progress lines as `render`.
        if (cpu) cpuRenderer = backends::makeRenderer(render::kCpuBackend, scene, options, {}, progress.callback());
        if (vulkan) {
          // Timing: validation layers would dominate.
          gpuRenderer = backends::makeRenderer(render::kVulkanBackend, scene, options,
                                               {a.device, false, slots, rays, a.queues, a.fusedLocalSize}, progress.callback());
          out["vulkan_device"] = gpuRenderer->deviceName();
          out["vulkan_rays"] = gpuRenderer->rays();
          out["vulkan_fused_local_size"] = a.fusedLocalSize;
        }
        if (cpuRenderer) out["cpu_device"] = cpuRenderer->deviceName();
        // Each object's level: the choice's, or under `auto` each one's own.
        const render::Renderer* first = cpuRenderer ? cpuRenderer.get() : gpuRenderer.get();
        HC_CHECK_EQ(first != nullptr, true);  // --backend names at least one
        const render::Renderer& any = *first;
        std::vector<int> objectLevels = any.objectLevels();
        if (objectLevels.empty()) objectLevels.assign(any.objectCount(), options.level);
        const std::string levelCell = choice.automatic ? level + " (" + render::describeLevels(objectLevels) + ")" : level;
        for (const auto& [width, height] : sizes) {
          render::FrameRequest request;
          request.width = width;
          request.height = height;
          request.camera = scene.camera;
          std::map<std::string, Measured> results;
          for (render::Renderer* r : {cpuRenderer.get(), gpuRenderer.get()}) {
            if (!r) continue;
            progress.message("level " + level + ", " + std::string(methodName(method)) + ", " +
                             std::to_string(width) + "×" + std::to_string(height) + ", " + r->backend() + ": " +
                             std::to_string(a.frames) + " frames + " + std::to_string(a.warmup) + " warm-up");
            results[r->backend()] = measure(*r, request, a.frames, a.warmup);
          }
          std::optional<std::pair<double, std::size_t>> agree;
          if (results.count(cpuName) && results.count(vulkanName)) agree = agreement(results[cpuName].first, results[vulkanName].first);
          for (const auto& [backend, m] : results) {
            nlohmann::json run{{"backend", backend},       {"level", level}, {"object_levels", objectLevels},
                               {"method", methodName(method)}, {"width", width},
                               {"height", height},         {"frame_seconds", m.frameSeconds},
                               {"fps", m.frameSeconds > 0.0 ? 1.0 / m.frameSeconds : 0.0},
                               {"coefficient_bytes", m.coefficientBytes}, {"covered_pixels", m.covered}};
            if (method == RotationMethod::Fused) {
              run["sum_tolerance"] = choiceOfSum.cells;
              run["smooth_sum_tolerance"] = choiceOfSum.smooth;
              run["directions_per_sample_mean"] = m.directionsMean;
              run["directions_per_sample_max"] = m.directionsMax;
            }
            nlohmann::json stages = nlohmann::json::object();
            for (const auto& [name, seconds] : m.stages) stages[name] = seconds;
            run["stages"] = stages;
            if (!m.parts.empty()) run["parts"] = m.parts;  // what the device's stages went to
            std::string ratio = "";
            if (backend == vulkanName && results.count(cpuName)) {
              const double r = results[cpuName].frameSeconds / m.frameSeconds;
              run["cpu_over_vulkan"] = r;
              nlohmann::json perStage = nlohmann::json::object();
              for (const auto& [name, seconds] : m.stages) {
                for (const auto& [cname, cseconds] : results[cpuName].stages) {
                  if (cname == name && seconds > 0.0) perStage[name] = cseconds / seconds;
                }
              }
              run["cpu_over_vulkan_stages"] = perStage;
              if (agree) {
                run["psnr_vs_cpu"] = std::isfinite(agree->first) ? nlohmann::json(agree->first) : nlohmann::json("inf");
                run["coverage_mismatched"] = agree->second;
              }
              char buf[96];
              std::snprintf(buf, sizeof buf, "×%.2f, %.1f dB, %zu px mismatched", r, agree ? agree->first : 0.0,
                            agree ? agree->second : 0);
              ratio = buf;
            }
            if (method == RotationMethod::Fused || method == RotationMethod::Splitsum) run["slices"] = a.slices;
            run["antialias"] = antialias;
            out["runs"].push_back(run);
            std::string row = "| " + levelCell + " | " + std::string(methodName(method)) + " | " + sum + " | " +
                              std::to_string(width) + "×" + std::to_string(height) + " | " + backend +
                              (backend == vulkanName && gpuRenderer ? " (rays " + gpuRenderer->rays() + ")" : "") + " |";
            for (const char* name :
                 {"light", "gbuffer", "rotation-input", "shadow-rays", "rotation", "triple-product", "fused", "tonemap"}) {
              double seconds = 0.0;
              for (const auto& [sname, s] : m.stages) {
                if (sname == name || (sname == "splitsum" && std::string(name) == "fused")) seconds = s;
              }
              char buf[32];
              std::snprintf(buf, sizeof buf, " %.4f |", seconds);
              row += buf;
            }
            char directions[48] = "";
            if (method == RotationMethod::Fused) std::snprintf(directions, sizeof directions, "%.0f, %zu", m.directionsMean, m.directionsMax);
            char buf[160];
            std::snprintf(buf, sizeof buf, " %.4f | %.2f | %zu | %s | %s |", m.frameSeconds,
                          m.frameSeconds > 0.0 ? 1.0 / m.frameSeconds : 0.0, m.coefficientBytes, directions, ratio.c_str());
            line(row + buf);
            rowDone("level " + level + ", " + std::string(methodName(method)) + ", " +
                        std::to_string(width) + "×" + std::to_string(height) + ", " + backend,
                    m.frameSeconds > 0.0 ? 1.0 / m.frameSeconds : 0.0);
          }
          if (gpuRenderer && !inFlight.empty()) {
            // The same renderer, its slots on their own queues where --vulkan-queues opened enough.
            std::string text = "frames in flight, " + std::to_string(width) + "×" + std::to_string(height) + ":";
            nlohmann::json measured = nlohmann::json::array();
            double one = 0.0;
            for (const std::size_t k : inFlight) {
              progress.message("frames in flight: " + std::to_string(k) + " at once, " + std::to_string(a.frames) + " frames each");
              const double fps = measureInFlight(*gpuRenderer, request, a.frames, k);
              if (k == 1) one = fps;
              measured.push_back({{"frames_in_flight", k}, {"fps_in_all", fps}});
              char buf[96];
              std::snprintf(buf, sizeof buf, "%s %zu: %.2f fps in all", k == inFlight.front() ? "" : ";", k, fps);
              text += buf;
              if (k != 1 && one > 0.0) {
                std::snprintf(buf, sizeof buf, " (%.2f× one)", fps / one);
                text += buf;
              }
            }
            out["runs"].back()["in_flight"] = measured;
            out["runs"].back()["frame_slots"] = gpuRenderer->framesInFlight();
            line("");
            line(text);
            line("");
            progress.message(text);
          }
        }
      }
    }
  }
  if (a.json) std::cout << out.dump(2) << '\n';
  return 0;
}

}  // namespace

std::function<int()> addBenchFrameCommand(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  auto* c = app.add_subcommand("bench-frame",
                               "Per-pass and frame times of the CPU and Vulkan backends against resolution and level");
  c->add_option("--backend", args->backend, backends::availableText() + " or both (both: ratios from one run)")->capture_default_str();
  c->add_option("--sizes", args->sizes, "Frame sizes, comma-separated: N for N×N, or WxH (e.g. 128,256,1920x1080)")
      ->capture_default_str();
  c->add_option("--levels", args->levels,
                "Map levels, comma-separated, each " + render::levelChoiceHelp() +
                    " (the split methods on Vulkan up to 6); e.g. auto,6 times automatic levels against level 6 in one run")
      ->capture_default_str();
  c->add_option("--method", args->methods, "Per-pixel methods, comma-separated (" + pixelMethodNames() + "), or all")
      ->capture_default_str();
  c->add_option("--antialias", args->antialias, "on|off: edge pixels as the mean of 4 sub-samples")
      ->capture_default_str();
  c->add_option("--slices", args->slices, "fused: blend the two nearest θo slices (blend) or take the nearest (nearest)")
      ->capture_default_str();
  c->add_option("--frames", args->frames, "Timed frames per point (after one warm-up frame)")->capture_default_str();
  c->add_option("--warmup", args->warmup, "Untimed frames first (resolution setup, first-use compilation)")
      ->capture_default_str();
  c->add_option("--scene", args->scene, "Scene file (default: the built-in scene)");
  c->add_option("--device", args->device, "Vulkan device: an index or a name substring");
  c->add_option("--rays", args->rays, rayModeHelp())->capture_default_str();
  c->add_option("--in-flight", args->inFlight,
                "Vulkan: frames rendered at once, comma-separated (e.g. 1,4): each as that many threads on one renderer "
                "with as many frame slots (each on a queue of its own where --vulkan-queues opens enough); frames per "
                "second in all, after each size's rows");
  c->add_option("--vulkan-queues", args->queues,
                "Vulkan: the most queues the device is opened with (0: every queue its family offers, at most 16; 1: "
                "every frame on one queue, the default)")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  c->add_option("--fused-local-size", args->fusedLocalSize,
                "Vulkan, fused: the workgroup size, a power of two up to 1024 (one workgroup sums a pixel's directions; 0: "
                "the device's default, 256 on a GPU, the subgroup on a CPU device)")
      ->check(CLI::IsMember({0u, 1u, 2u, 4u, 8u, 16u, 32u, 64u, 128u, 256u, 512u, 1024u}))
      ->capture_default_str();
  c->add_option("--sum-tolerance", args->sumTolerances,
                sumToleranceHelp() + "; comma-separated, one run each: e.g. 0,0.1 times both")
      ->capture_default_str();
  c->add_option("--smooth-sum", args->smoothSums,
                smoothSumHelp() + "; comma-separated, one run each with each --sum-tolerance: e.g. 0,0.01 times both")
      ->capture_default_str();
  c->add_option("--object-sky", args->objectSky, "fused: objects hide sky from each other (true|false: its cost, side by side)")
      ->capture_default_str();
  c->add_option("--cache-dir", args->cacheDir, "Cache of slice tables and visibility ('none' or empty: no cache)");
  c->add_flag("--json", args->json, "Print JSON instead of a table");
  return [c, args]() { return c->parsed() ? run(*args) : -1; };
}

}  // namespace haarcast::app
