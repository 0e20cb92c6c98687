// The CPU reference backend behind the Renderer interface: Embree primary
// rays, per-pixel shading on a thread pool, edge pixels antialiased. Frames
// may render concurrently (each borrows its own posed ray scene) and stop at
// the next row once the request's `cancelled` says so.
#include "haarcast/render/renderer.h"

#include <algorithm>
#include <bit>
#include <limits>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <functional>
#include <mutex>
#include <thread>

#include <glm/geometric.hpp>

#include "haarcast/core/check.h"
#include "haarcast/core/parallel.h"
#include "haarcast/core/shared_smooth.h"
#include "haarcast/core/rotate_haar.h"
#include "haarcast/core/splitsum.h"
#include "haarcast/core/triple_product.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/backend_names.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/render/exposure_meter.h"
#include "haarcast/render/point_lights.h"
#include "haarcast/render/shading.h"

namespace haarcast::render {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Thrown at a tile boundary once the request's `cancelled` says so; it stops
// parallelFor from handing out further rows (parallel.h) and render() turns
// it into a cancelled Frame. Private to this file: it never leaves render().
struct FrameCancelled {};

// The tile-boundary check: a tile is one row of a pass (or a run of edge
// pixels), so a cancelled frame stops after at most the rows in flight.
// Each tile is also counted in the frame's stage (frame_stage.h): the
// watcher's fraction of the stage is the tiles started over the tiles the
// stage said it has.
class CancelPoint {
 public:
  explicit CancelPoint(const FrameRequest& request) : request_(request) {}
  void operator()() const {
    if (request_.cancelled && request_.cancelled()) throw FrameCancelled{};
    tickFrameStage(request_);
  }

 private:
  const FrameRequest& request_;
};

class CpuRenderer final : public Renderer {
 public:
  CpuRenderer(const Scene& scene, const RenderOptions& options, const RenderProgress& progress)
      : options_(options), prepared_(prepareScene(scene, options, progress)) {
    for (const PreparedObject& p : prepared_.objects) {
      if (options.method == RotationMethod::Splitsum) continue;  // its lobes are all it keeps (prepareScene)
      if (options.method == RotationMethod::Fused) {
        // The only per-object data fused keeps: the unrotated slices in pixel form.
        pixelSlices_.push_back(PixelSlices::synthesize(p.table, p.finerPointTable(), p.sumTolerance > 0.0f));
        continue;
      }
      // matrix and table precompute per channel for seconds at level 6
      // (elevation matrices, pre-rotated copies): reported as a stage.
      const std::string stage = "rotators " + p.name;
      std::array<std::unique_ptr<SliceRotator>, 3> r;
      for (std::size_t c = 0; c < r.size(); ++c) {
        if (progress) progress(stage, c, r.size());
        r[c] = makeRotator(options.method, p.table.channelSlices(static_cast<int>(c)), options.rotator);
      }
      if (progress) progress(stage, r.size(), r.size());
      rotators_.push_back(std::move(r));
      // haar refined rotates the three channels together, sharing the
      // geometry and the cell walk (rotate_haar.h).
      if (options.method == RotationMethod::Haar && options.rotator.haarVariant == HaarVariant::Refined) {
        rgbHaar_.push_back(std::make_unique<RgbHaarRotator>(
            std::array<std::vector<HaarMap>, 3>{p.table.channelSlices(0), p.table.channelSlices(1), p.table.channelSlices(2)},
            options.rotator));
      } else {
        rgbHaar_.push_back(nullptr);
      }
    }
    // The meshes' ray structures are built once; frames only move them.
    idleWork_.push_back(makeWork());
  }

  std::string backend() const override { return std::string(kCpuBackend); }
  std::string deviceName() const override {
    // The threads and the SIMD target the fused pass dispatched to on this
    // machine, for reports. (Not "reference": that is the Monte Carlo truth,
    // `haarcast reference`.)
    return "cpu (" + std::to_string(hardwareThreads(options_.threads)) + " threads" +
           (options_.method == RotationMethod::Fused ? ", " + fusedTargetName() + " kernels" : std::string()) + ")";
  }
  const RenderOptions& options() const override { return options_; }
  std::size_t objectCount() const override { return prepared_.objects.size(); }
  std::vector<int> objectLevels() const override { return prepared_.objectLevels(); }
  std::vector<int> pointLightLevels() const override { return prepared_.pointLightLevels(); }
  std::vector<std::string> objectPlans() const override { return prepared_.objectPlans(); }
  bool concurrentRenders() const override { return true; }

  Frame render(const FrameRequest& request) override;

 private:
  static unsigned hardwareThreads(unsigned t) { return t ? t : std::max(1u, std::thread::hardware_concurrency()); }
  std::unique_ptr<RayScene> makeRays() const {
    std::vector<Instance> instances;
    for (const PreparedObject& p : prepared_.objects) instances.push_back({p.mesh.get(), glm::mat4(p.pose.objectToWorld())});
    return std::make_unique<RayScene>(std::move(instances));
  }
  // A frame poses its objects in a ray scene (setTransform), which no other
  // frame may query meanwhile, and fills a G-buffer: each concurrent render
  // borrows both from the pool, built on first need (the concurrency the
  // server runs, at most), and returns them when done. The G-buffer keeps its
  // storage between frames: at 1280×720 it is ~140 MB, which a frame that
  // allocated it afresh paid for in page faults (~6 % of its time).
  // Everything else a frame reads is immutable.
  struct GBuffer;
  struct FusedSlots;
  struct FrameWork;
  class FrameLease {
   public:
    explicit FrameLease(const CpuRenderer& r) : owner_(r) {
      {
        const std::lock_guard lock(owner_.workMutex_);
        if (!owner_.idleWork_.empty()) {
          work_ = std::move(owner_.idleWork_.back());
          owner_.idleWork_.pop_back();
        }
      }
      if (!work_) work_ = owner_.makeWork();
    }
    ~FrameLease() {
      const std::lock_guard lock(owner_.workMutex_);
      owner_.idleWork_.push_back(std::move(work_));
    }
    FrameLease(const FrameLease&) = delete;
    FrameLease& operator=(const FrameLease&) = delete;
    RayScene& rays() const;
    GBuffer& gbuffer() const;
    FusedSlots& fusedSlots() const;
    // Lets go of storage kept from a frame over twice this one's size, so a
    // single large frame does not hold its memory for the renderer's life.
    void fitTo(std::size_t pixels) const;

   private:
    const CpuRenderer& owner_;
    std::unique_ptr<FrameWork> work_;
  };
  Frame renderFrame(const FrameRequest& request, const CancelPoint& cancelPoint) const;
  // Bytes one rotation of one channel reads: the slice, plus for `matrix`
  // the two elevation matrices it blends and for `table` the stored copy
  // (which replaces the slice).
  std::size_t rotationBytes(std::size_t object) const;

  struct PixelInput {
    RotationInput rotation;
    double b[3];
    unsigned vertex[3];
  };
  // One shaded sample: the centre of a covered pixel, or a covered
  // sub-sample of an edge pixel (shared::kSubsamples of them).
  struct Sample {
    Hit hit;
    std::uint32_t pixel = 0;    // y·width + x of its pixel (sub-samples too)
    glm::dvec3 direction{0.0};  // of the camera ray, world frame
    PixelInput input;           // filled by the rotation-input stage
  };
  static constexpr std::uint32_t kInterior = ~0u;
  // The frame's primary visibility: the centre sample of every pixel, and
  // for each edge pixel (edge[i] ≠ kInterior) its sub-samples.
  struct GBuffer {
    std::vector<std::optional<Sample>> centre;
    std::vector<std::uint32_t> edge;
    std::vector<std::array<std::optional<Sample>, shared::kSubsamples>> sub;
    std::size_t width = 0, height = 0;
  };
  // fused's per-sample records, by slot (shadeFused).
  struct FusedSlots {
    std::vector<ShadingPoint> points;
    std::vector<std::uint32_t> lightsSeen;     // the point lights each sees
    // By pixel, with a smooth-sum tolerance (core/shared_smooth.h): the centre
    // sample's sum and radiance, and whether it was summed or taken.
    std::vector<std::array<float, 3>> sums, shaded;
    std::vector<glm::vec3> mirrors;  // shared::smoothMirror
    std::vector<std::uint8_t> centreState;
    // The object whose sum each pixel's centre takes part in, or −1
    // (shadeSmoothSums): what its stages read of the G-buffer, two bytes a
    // pixel rather than a sample's.
    std::vector<std::int16_t> visitObject;
  };
  struct FrameWork {
    std::unique_ptr<RayScene> rays;
    GBuffer gbuffer;
    FusedSlots fusedSlots;
  };
  std::unique_ptr<FrameWork> makeWork() const {
    auto w = std::make_unique<FrameWork>();
    w->rays = makeRays();
    return w;
  }
  // gbuffer: traces the centres, finds the edge pixels, traces their
  // sub-samples. rotation-input: each sample's slice and Euler angles.
  void traceGBuffer(const RayScene& rays, const CameraRays& camera, int w, int h, GBuffer& g,
                    const CancelPoint& cancelPoint) const;
  void fillInputs(const ResolvedFrame& resolved, GBuffer& g, const CancelPoint& cancelPoint) const;
  // rgb = the sample's radiance; returns the coefficient bytes read.
  // `slot` numbers the frame's samples: a centre by its pixel, sub-sample k
  // of edge pixel e after them, pixels + e·kSubsamples + k (sampleSlot).
  using Shade = std::function<std::size_t(const Sample&, std::size_t slot, std::array<float, 3>& rgb)>;
  // Every covered pixel: the centre sample shaded, or for an edge pixel the
  // mean of its sub-samples (the backdrop where one misses); rows in
  // parallel. Marks objectMask; returns the bytes read.
  std::size_t shadePixels(const GBuffer& g, const FrameRequest& request, const CameraRays& camera, Frame& frame,
                          const Shade& shade, const CancelPoint& cancelPoint) const;
  // The per-pixel passes: rotation + triple product (the rotating methods),
  // or one fused pass. Each adds its stages and returns the bytes read.
  std::size_t shadeRotating(const ResolvedFrame& resolved, const GBuffer& g, const FrameRequest& request,
                            const CameraRays& camera, Frame& frame, const CancelPoint& cancelPoint) const;
  // Each object's placement and turn this frame, as shadingPoint takes them.
  struct ObjectFrames {
    std::vector<glm::mat4> toWorld;
    std::vector<glm::mat3> rotations;
    explicit ObjectFrames(const ResolvedFrame& resolved);
  };
  // The world point, normal and shadow-ray offset of a sample on `object`
  // (point_lights.h), for the shadow rays `fused` and `splitsum` cast.
  ShadingPoint samplePoint(const ObjectFrames& frames, const ResolvedFrame& resolved, std::size_t object,
                           const PixelInput& in) const;
  std::size_t shadeFused(const ResolvedFrame& resolved, const RayScene& rays, const GBuffer& g, FusedSlots& slotRecords,
                         const FrameRequest& request, const CameraRays& camera, Frame& frame,
                         const CancelPoint& cancelPoint) const;
  // One fused sample: the bytes read, the directions summed (0 for the
  // ground, the lobe path alone, or a given sum).
  struct Shaded {
    std::size_t bytes = 0, directions = 0;
    bool pass = false;  // an object sample of the pass (not the ground)
  };
  using ShadeFusedSample = std::function<Shaded(const Sample&, std::size_t slot, std::array<float, 3>& rgb, FusedSum* sum)>;
  // With a smooth-sum tolerance: the interior pixels' centre samples on the
  // pass's objects, coarse to fine (core/shared_smooth.h), into `slots`' sums,
  // shaded and centreState; `count` takes each one's directions. Returns
  // the bytes read.
  static constexpr std::uint8_t kNotVisited = 0, kSummed = 1, kTaken = 2;
  std::size_t shadeSmoothSums(const GBuffer& g, FusedSlots& slots, const ShadeFusedSample& shade,
                              const std::function<void(std::size_t)>& count, std::size_t& smoothSamples,
                              const CancelPoint& cancelPoint) const;
  std::size_t shadeSplitsum(const ResolvedFrame& resolved, const RayScene& rays, const GBuffer& g,
                            const FrameRequest& request, const CameraRays& camera, Frame& frame,
                            const CancelPoint& cancelPoint) const;

  RenderOptions options_;
  PreparedScene prepared_;
  std::vector<std::array<std::unique_ptr<SliceRotator>, 3>> rotators_;  // rotating methods
  std::vector<std::unique_ptr<RgbHaarRotator>> rgbHaar_;                 // haar refined, else null
  std::vector<PixelSlices> pixelSlices_;                                 // fused
  // Ray scenes and G-buffers not in use by a frame (FrameLease); the ray
  // scenes posed per frame with setTransform (top level only).
  mutable std::mutex workMutex_;
  mutable std::vector<std::unique_ptr<FrameWork>> idleWork_;
};

RayScene& CpuRenderer::FrameLease::rays() const { return *work_->rays; }
CpuRenderer::GBuffer& CpuRenderer::FrameLease::gbuffer() const { return work_->gbuffer; }
CpuRenderer::FusedSlots& CpuRenderer::FrameLease::fusedSlots() const { return work_->fusedSlots; }
void CpuRenderer::FrameLease::fitTo(std::size_t pixels) const {
  if (work_->gbuffer.centre.capacity() <= 2 * pixels) return;
  work_->gbuffer = GBuffer{};
  work_->fusedSlots = FusedSlots{};
}

std::size_t CpuRenderer::rotationBytes(std::size_t object) const {
  const std::size_t slice = static_cast<std::size_t>(mapSize(options_.level)) * static_cast<std::size_t>(mapSize(options_.level)) * sizeof(float);
  if (options_.method != RotationMethod::Matrix) return slice;
  const SliceRotator& r = *rotators_[object][0];
  const std::size_t matrices = r.storedBytes() - slice * r.sliceCount();
  return slice + 2 * matrices / static_cast<std::size_t>(std::max(1, options_.rotator.matrixElevations));
}

void CpuRenderer::traceGBuffer(const RayScene& rays, const CameraRays& camera, int w, int h, GBuffer& g,
                               const CancelPoint& cancelPoint) const {
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  auto trace = [&](const glm::dvec3& direction, std::size_t pixel) -> std::optional<Sample> {
    Ray r;
    r.origin = glm::vec3(camera.origin());
    r.direction = glm::vec3(direction);
    const std::optional<Hit> hit = rays.intersect(r);
    if (!hit) return std::nullopt;
    Sample s;
    s.hit = *hit;
    s.pixel = static_cast<std::uint32_t>(pixel);
    s.direction = direction;
    return s;
  };
  g.centre.assign(pixels, std::nullopt);
  g.width = static_cast<std::size_t>(w);
  g.height = static_cast<std::size_t>(h);
  // The centres in 4×4 tiles, one Embree packet each (RayScene::intersectFrom:
  // neighbouring rays from the eye share their traversal), bands of 4 rows
  // in parallel.
  constexpr int kTile = 4;
  const glm::vec3 eye(camera.origin());
  parallelFor(static_cast<std::size_t>((h + kTile - 1) / kTile), [&](std::size_t band) {
    cancelPoint();
    std::array<glm::dvec3, kTile * kTile> exact;
    std::array<glm::vec3, kTile * kTile> directions;
    std::array<std::size_t, kTile * kTile> pixel;
    std::array<std::optional<Hit>, kTile * kTile> hits;
    const int y0 = static_cast<int>(band) * kTile, y1 = std::min(y0 + kTile, h);
    for (int x0 = 0; x0 < w; x0 += kTile) {
      std::size_t n = 0;
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < std::min(x0 + kTile, w); ++x, ++n) {
          exact[n] = camera.direction(x, y);
          directions[n] = glm::vec3(exact[n]);
          pixel[n] = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
        }
      }
      rays.intersectFrom(eye, 0.0f, std::span(directions).first(n), std::span(hits).first(n));
      for (std::size_t k = 0; k < n; ++k) {
        if (!hits[k]) continue;
        Sample s;
        s.hit = *hits[k];
        s.pixel = static_cast<std::uint32_t>(pixel[k]);
        s.direction = exact[k];
        g.centre[pixel[k]] = s;
      }
    }
  }, {}, options_.threads);

  // Edge pixels (shared_layout.h): the 3×3 centres do not agree on the object.
  g.edge.assign(pixels, kInterior);
  g.sub.clear();
  if (!options_.antialias) return;
  auto id = [&](int x, int y) -> std::size_t {
    const auto& c = g.centre[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
    return c ? c->hit.object + 1 : 0;
  };
  // Rows in parallel mark their edge pixels (0); one pass numbers them in
  // pixel order.
  parallelFor(static_cast<std::size_t>(h), [&](std::size_t row) {
    cancelPoint();
    const int y = static_cast<int>(row);
    for (int x = 0; x < w; ++x) {
      const std::size_t mine = id(x, y);
      bool edge = false;
      for (int dy = -1; dy <= 1 && !edge; ++dy)
        for (int dx = -1; dx <= 1 && !edge; ++dx) edge = id(std::clamp(x + dx, 0, w - 1), std::clamp(y + dy, 0, h - 1)) != mine;
      if (edge) g.edge[row * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] = 0;
    }
  }, {}, options_.threads);
  cancelPoint();
  std::uint32_t edges = 0;
  for (std::uint32_t& e : g.edge)
    if (e != kInterior) e = edges++;
  g.sub.resize(edges);
  parallelFor(static_cast<std::size_t>(h), [&](std::size_t y) {
    cancelPoint();
    for (int x = 0; x < w; ++x) {
      const std::uint32_t e = g.edge[y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
      if (e == kInterior) continue;
      for (unsigned k = 0; k < shared::kSubsamples; ++k)
        g.sub[e][k] = trace(camera.subsampleDirection(x, static_cast<int>(y), k), y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x));
    }
  }, {}, options_.threads);
}

void CpuRenderer::fillInputs(const ResolvedFrame& resolved, GBuffer& g, const CancelPoint& cancelPoint) const {
  // The interpolated normal and the view direction in the object's frame.
  auto fill = [&](Sample& s) {
    const PreparedObject& p = prepared_.objects[s.hit.object];
    const Mesh& mesh = *p.mesh;
    const glm::uvec3 tri = mesh.triangles[s.hit.triangle];
    PixelInput& in = s.input;
    in.b[0] = 1.0 - s.hit.u - s.hit.v;
    in.b[1] = s.hit.u;
    in.b[2] = s.hit.v;
    in.vertex[0] = tri.x;
    in.vertex[1] = tri.y;
    in.vertex[2] = tri.z;
    // fused shades the ground in closed form from its shading point alone
    // (shadeFused), so most of a frame's samples need no slice or angles.
    if (p.ground && options_.method == RotationMethod::Fused) return;
    const glm::dvec3 n = glm::normalize(in.b[0] * glm::dvec3(mesh.normals[tri.x]) + in.b[1] * glm::dvec3(mesh.normals[tri.y]) +
                                        in.b[2] * glm::dvec3(mesh.normals[tri.z]));
    const glm::dvec3 wo = glm::transpose(resolved.objects[s.hit.object].rotation) * -s.direction;
    in.rotation = options_.method == RotationMethod::Splitsum ? rotationInput(n, wo) : rotationInput(n, wo, p.table);
  };
  // In rows (and runs of 64 edge pixels): one task per pixel would cost
  // more in scheduling than the work.
  parallelFor(g.height, [&](std::size_t y) {
    cancelPoint();
    for (std::size_t i = y * g.width; i < (y + 1) * g.width; ++i)
      if (g.centre[i]) fill(*g.centre[i]);
  }, {}, options_.threads);
  parallelFor((g.sub.size() + 63) / 64, [&](std::size_t run) {
    cancelPoint();
    for (std::size_t e = run * 64; e < std::min(g.sub.size(), run * 64 + 64); ++e)
      for (auto& s : g.sub[e])
        if (s) fill(*s);
  }, {}, options_.threads);
}

std::size_t CpuRenderer::shadePixels(const GBuffer& g, const FrameRequest& request, const CameraRays& camera,
                                     Frame& frame, const Shade& shade, const CancelPoint& cancelPoint) const {
  const int w = frame.width, h = frame.height;
  const glm::mat3 toEnvironment(glm::transpose(lightRotationOf(prepared_, request)));  // the backdrop's, as the tonemap stage's
  std::atomic<std::size_t> total{0};
  parallelFor(static_cast<std::size_t>(h), [&](std::size_t y) {
    cancelPoint();
    std::size_t rowBytes = 0;
    std::array<float, 3> rgb{};
    for (int x = 0; x < w; ++x) {
      const std::size_t i = y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      if (g.centre[i]) frame.objectMask[i] = 1;
      if (g.edge[i] == kInterior) {
        if (!g.centre[i]) continue;  // the backdrop, drawn by the tonemap stage
        rowBytes += shade(*g.centre[i], i, rgb);
        for (int c = 0; c < 3; ++c) frame.image.at(static_cast<int>(y), x, c) = rgb[static_cast<std::size_t>(c)];
        continue;
      }
      glm::dvec3 sum(0.0);
      for (unsigned k = 0; k < shared::kSubsamples; ++k) {
        const auto& s = g.sub[g.edge[i]][k];
        if (s) {
          rowBytes += shade(*s, g.centre.size() + g.edge[i] * shared::kSubsamples + k, rgb);
          sum += glm::dvec3(rgb[0], rgb[1], rgb[2]);
        } else if (options_.environmentBackground) {
          sum += glm::dvec3(backdropRadiance(prepared_.background, toEnvironment,
                                             glm::vec3(camera.subsampleDirection(x, static_cast<int>(y), k))));
        }
      }
      sum /= static_cast<double>(shared::kSubsamples);
      for (int c = 0; c < 3; ++c) frame.image.at(static_cast<int>(y), x, c) = static_cast<float>(sum[c]);
    }
    total += rowBytes;
  }, {}, options_.threads);
  return total.load();
}

Frame CpuRenderer::render(const FrameRequest& request) {
  const CancelPoint cancelPoint(request);
  try {
    return renderFrame(request, cancelPoint);
  } catch (const FrameCancelled&) {
    Frame frame;
    frame.width = request.width;
    frame.height = request.height;
    frame.cancelled = true;
    return frame;
  }
}

Frame CpuRenderer::renderFrame(const FrameRequest& request, const CancelPoint& cancelPoint) const {
  const auto start = Clock::now();
  Frame frame;

  // ---- light: world → each object's frame, once per frame -----------------
  auto t0 = Clock::now();
  enterFrameStage(request, "light");
  const ResolvedFrame resolved = resolveFrame(prepared_, options_, request);
  std::size_t bytes = resolved.lightBytes;
  frame.stages.push_back({"light", since(t0)});

  // ---- gbuffer, rotation-input: Embree primary rays, per-sample inputs ----
  cancelPoint();
  const FrameLease lease(*this);
  RayScene& rays = lease.rays();
  for (std::size_t i = 0; i < resolved.objects.size(); ++i) rays.setTransform(i, glm::mat4(resolved.objects[i].objectToWorld));
  const int w = request.width, h = request.height;
  frame.width = w;
  frame.height = h;
  const CameraRays camera(request.camera, w, h);
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  GBuffer& g = lease.gbuffer();
  lease.fitTo(pixels);
  t0 = Clock::now();
  // Its tiles: the 4-row bands of centres, then with antialiasing the edge
  // search's rows, one check, and the edge samples' rows (traceGBuffer).
  const std::size_t rows = static_cast<std::size_t>(h);
  enterFrameStage(request, "gbuffer", (rows + 3) / 4 + (options_.antialias ? 2 * rows + 1 : 0));
  traceGBuffer(rays, camera, w, h, g, cancelPoint);
  frame.stages.push_back({"gbuffer", since(t0)});
  t0 = Clock::now();
  enterFrameStage(request, "rotation-input", rows + (g.sub.size() + 63) / 64);
  fillInputs(resolved, g, cancelPoint);
  frame.stages.push_back({"rotation-input", since(t0)});

  frame.image = io::makeImage(w, h);
  frame.objectMask.assign(pixels, 0);
  // The rotating methods rotate and multiply pixel by pixel: one stage
  // entered, "rotation", for both.
  // Their tiles: the rows of shadePixels, and fused's row pass of shadow
  // rays before it.
  enterFrameStage(request,
                  options_.method == RotationMethod::Fused      ? "fused"
                  : options_.method == RotationMethod::Splitsum ? "splitsum"
                                                                : "rotation",
                  options_.method == RotationMethod::Fused ? 2 * rows : rows);
  switch (options_.method) {
    case RotationMethod::Fused: bytes += shadeFused(resolved, rays, g, lease.fusedSlots(), request, camera, frame, cancelPoint); break;
    case RotationMethod::Splitsum: bytes += shadeSplitsum(resolved, rays, g, request, camera, frame, cancelPoint); break;
    default: bytes += shadeRotating(resolved, g, request, camera, frame, cancelPoint); break;
  }

  // ---- tonemap: backdrop, RGBA8 --------------------------------------------
  t0 = Clock::now();
  enterFrameStage(request, "tonemap", options_.environmentBackground ? rows : 0);
  if (options_.environmentBackground) {
    const glm::mat3 toEnvironment(glm::transpose(lightRotationOf(prepared_, request)));  // once, not per pixel
    parallelFor(static_cast<std::size_t>(h), [&](std::size_t y) {
      cancelPoint();
      for (int x = 0; x < w; ++x) {
        const std::size_t i = y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
        if (frame.objectMask[i] || g.edge[i] != kInterior) continue;  // drawn by the shading
        const glm::vec3 L = backdropRadiance(prepared_.background, toEnvironment, glm::vec3(camera.direction(x, static_cast<int>(y))));
        for (int c = 0; c < 3; ++c) frame.image.at(static_cast<int>(y), x, c) = static_cast<float>(L[c]);
      }
    }, {}, options_.threads);
  }
  const shared::ExposureResult exposure =
      meterExposure(frame.image, frame.objectMask, request.exposure, request.tone, options_.threads);
  frame.logAverageLuminance = exposure.logAverage;
  // A fixed exposure is reported as asked, as the Vulkan backend does.
  frame.exposureStops = request.exposure.automatic ? static_cast<double>(exposure.stops) : request.exposure.stops;
  frame.rgba8 = tonemapRgba8(frame.image, frame.exposureStops, request.tone, options_.threads);
  frame.stages.push_back({"tonemap", since(t0)});
  frame.coefficientBytes = bytes;
  frame.seconds = since(start);
  return frame;
}

std::size_t CpuRenderer::shadeRotating(const ResolvedFrame& resolved, const GBuffer& g, const FrameRequest& request,
                                       const CameraRays& camera, Frame& frame, const CancelPoint& cancelPoint) const {
  // The light's lists are validated and put in the walk's order once per frame.
  std::vector<std::array<PreparedLight, 3>> light(resolved.objects.size());
  for (std::size_t i = 0; i < light.size(); ++i)
    for (std::size_t c = 0; c < 3; ++c) light[i][c].assign(resolved.objects[i].light[c]);
  // The CPU keeps one rotated map per thread instead of a frame's worth, so
  // the two stages run interleaved; their wall time is split in proportion
  // to the thread time each took.
  const auto t0 = Clock::now();
  std::atomic<std::int64_t> rotationNs{0}, productNs{0};
  const std::size_t bytes = shadePixels(g, request, camera, frame, [&](const Sample& sample, std::size_t /*slot*/, std::array<float, 3>& rgb) {
    // Per worker thread, kept across pixels: no allocation per pixel once warm.
    struct Scratch {
      std::array<HaarMap, 3> rotated;
      HaarRotationScratch haar;
      SparseHaar merged;
      PreparedVisibility visibility;
    };
    thread_local Scratch s;
    const std::size_t object = sample.hit.object;
    const PreparedObject& p = prepared_.objects[object];
    const PixelInput& in = sample.input;
    const auto a = Clock::now();
    const std::size_t slice = static_cast<std::size_t>(in.rotation.slice);
    if (rgbHaar_[object]) {
      rgbHaar_[object]->rotate(slice, in.rotation.euler, s.rotated, s.haar);
    } else {
      for (std::size_t c = 0; c < 3; ++c) rotators_[object][c]->rotate(slice, in.rotation.euler, s.rotated[c]);
    }
    const auto b = Clock::now();
    // The product is linear in V: the three vertices' lists merged with
    // their barycentric weights, then one product per channel.
    const std::array<const SparseHaar*, 3> vertices{&p.visibility[in.vertex[0]], &p.visibility[in.vertex[1]],
                                                    &p.visibility[in.vertex[2]]};
    mergeVisibility(vertices, {in.b[0], in.b[1], in.b[2]}, s.merged);
    s.visibility.assign(s.merged);
    for (std::size_t c = 0; c < 3; ++c) rgb[c] = static_cast<float>(tripleProduct(light[object][c], s.rotated[c], s.visibility));
    rotationNs += std::chrono::duration_cast<std::chrono::nanoseconds>(b - a).count();
    productNs += std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - b).count();
    std::size_t read = 3 * rotationBytes(object);
    for (const SparseHaar* v : vertices) read += v->size() * (sizeof(std::uint32_t) + sizeof(float));
    return read;
  }, cancelPoint);
  const double shading = since(t0);
  const double busy = static_cast<double>(rotationNs.load() + productNs.load());
  const double rotationShare = busy > 0.0 ? static_cast<double>(rotationNs.load()) / busy : 0.5;
  frame.stages.push_back({"rotation", shading * rotationShare});
  frame.stages.push_back({"triple-product", shading * (1.0 - rotationShare)});
  return bytes;
}

CpuRenderer::ObjectFrames::ObjectFrames(const ResolvedFrame& resolved) {
  for (const ResolvedObject& o : resolved.objects) {
    toWorld.emplace_back(o.objectToWorld);
    rotations.emplace_back(o.rotation);
  }
}

ShadingPoint CpuRenderer::samplePoint(const ObjectFrames& frames, const ResolvedFrame& resolved, std::size_t object,
                                      const PixelInput& in) const {
  const PreparedObject& p = prepared_.objects[object];
  const float b[3] = {static_cast<float>(in.b[0]), static_cast<float>(in.b[1]), static_cast<float>(in.b[2])};
  return shadingPoint(*p.mesh, glm::uvec3(in.vertex[0], in.vertex[1], in.vertex[2]), b, frames.toWorld[object],
                      frames.rotations[object], p.shadowShift * static_cast<float>(resolved.objects[object].scale));
}

std::size_t CpuRenderer::shadeFused(const ResolvedFrame& resolved, const RayScene& rays, const GBuffer& g,
                                    FusedSlots& slotRecords, const FrameRequest& request, const CameraRays& camera, Frame& frame,
                                    const CancelPoint& cancelPoint) const {
  const auto t0 = Clock::now();
  // The stage's parts (Frame::parts), each from the mark before it.
  auto partStart = t0;
  auto markPart = [&](const char* name) {
    const auto now = Clock::now();
    frame.parts.push_back({std::string("fused: ") + name, std::chrono::duration<double>(now - partStart).count()});
    partStart = now;
  };
  const ObjectFrames frames(resolved);
  const glm::vec3 eye(camera.origin());
  // The ground's hidden sky on the coarse grid (point_lights.h), from the
  // interior pixels' centre samples, as the Vulkan backend takes them.
  GroundSkyGrid sky(frame.width, frame.height);
  if (prepared_.ground) {
    sky.compute(rays, resolved.skyOccluders, [&](std::size_t pixel) -> std::optional<ShadingPoint> {
      auto ground = [&](std::size_t i) { return g.centre[i] && prepared_.objects[g.centre[i]->hit.object].ground; };
      // Interior ground pixels only (the 3×3 rule of shared_layout.h), with
      // antialiasing or without, as the Vulkan backend.
      if (!ground(pixel) || !interiorPixel(pixel, g.width, g.height, ground)) return std::nullopt;
      const std::optional<Sample>& c = g.centre[pixel];
      return samplePoint(frames, resolved, c->hit.object, c->input);
    }, options_.threads);
  }
  markPart("ground sky grid");
  // Each sample's shading point, and the point lights it sees: one shadow
  // ray each (point_lights.h), a pixel row's samples at a time so that each
  // light's rays go in packets. By slot (Shade), for the pass below, which
  // casts the hidden sky's rays of the samples that sum their own.
  const std::size_t slotCount = g.centre.size() + g.sub.size() * shared::kSubsamples;
  std::vector<ShadingPoint>& points = slotRecords.points;
  std::vector<std::uint32_t>& lightsSeen = slotRecords.lightsSeen;
  points.resize(slotCount);  // each slot a sample takes is written below
  lightsSeen.assign(slotCount, 0u);
  const SkyOccluders& occluders = resolved.skyOccluders;
  parallelFor(g.height, [&](std::size_t y) {
    cancelPoint();
    thread_local std::vector<ShadingPoint> row;
    thread_local std::vector<std::size_t> slots;
    thread_local std::vector<std::uint32_t> masks;
    thread_local std::vector<std::uint8_t> onGround;
    row.clear();
    slots.clear();
    onGround.clear();
    auto add = [&](const Sample& s, std::size_t slot) {
      const std::size_t object = s.hit.object;
      points[slot] = samplePoint(frames, resolved, object, s.input);
      row.push_back(points[slot]);
      slots.push_back(slot);
      onGround.push_back(prepared_.objects[object].ground ? 1 : 0);
    };
    for (std::size_t i = y * g.width; i < (y + 1) * g.width; ++i) {
      if (g.edge[i] == kInterior) {
        if (g.centre[i]) add(*g.centre[i], i);
        continue;
      }
      for (unsigned k = 0; k < shared::kSubsamples; ++k)
        if (const auto& s = g.sub[g.edge[i]][k]) add(*s, g.centre.size() + g.edge[i] * shared::kSubsamples + k);
    }
    if (resolved.pointLightDirections.empty()) return;
    masks.resize(row.size());
    pointLightMasks(rays, row, resolved.pointLightDirections, masks, GroundRays{occluders.occluders, onGround});
    for (std::size_t j = 0; j < slots.size(); ++j) lightsSeen[slots[j]] = masks[j];
  }, {}, options_.threads);
  markPart("points and rays");
  // What the pass visited (Frame::passDirections), over the object samples.
  std::atomic<std::size_t> passSamples{0}, passDirections{0}, passDirectionsMax{0};
  auto count = [&](std::size_t directions) {
    passSamples.fetch_add(1, std::memory_order_relaxed);
    passDirections.fetch_add(directions, std::memory_order_relaxed);
    for (std::size_t most = passDirectionsMax.load(std::memory_order_relaxed);
         directions > most && !passDirectionsMax.compare_exchange_weak(most, directions);) {
    }
  };
  auto shadeSample = [&](const Sample& sample, std::size_t slot, std::array<float, 3>& rgb, FusedSum* sum) -> Shaded {
    // Per worker thread, kept across pixels: no allocation per pixel.
    thread_local FusedScratch scratch;
    const std::size_t object = sample.hit.object;
    const PreparedObject& p = prepared_.objects[object];
    const ResolvedObject& o = resolved.objects[object];
    const PixelInput& in = sample.input;
    const ShadingPoint& point = points[slot];
    std::uint32_t seen = lightsSeen[slot];
    if (p.lobePath) seen |= lobeRayBit(rays, point, eye);
    if (p.ground) {
      // The word the Vulkan backend reads too: bits, then the sky's occlusion.
      seen = withGroundOcclusion(seen, sky.at(sample.pixel, [&] { return groundSkyOcclusion(rays, point, resolved.skyOccluders); }));
      const float kept = shared::groundSkyKept(seen);
      // In registers, over the lights it sees, in order.
      glm::vec3 radiance = kept * glm::vec3(o.groundFlat[0], o.groundFlat[1], o.groundFlat[2]);
      const std::uint32_t lights = (1u << o.pointLights.size()) - 1u;  // at most kMaxPointLights < 32
      for (std::uint32_t bits = seen & lights; bits != 0u; bits &= bits - 1u) {
        const FusedPointLight& light = o.pointLights[static_cast<std::size_t>(std::countr_zero(bits))];
        radiance += glm::vec3(light.power[0], light.power[1], light.power[2]);
      }
      rgb = {radiance.x, radiance.y, radiance.z};
      return Shaded{};
    }
    std::array<WeightedBits, 3> vis;
    for (std::size_t v = 0; v < 3; ++v)
      vis[v] = {p.visibilityBits.point(in.vertex[v]).data(), static_cast<float>(in.b[v]),
                p.cellVisibility.empty() ? nullptr : p.cellVisibility.point(in.vertex[v])};
    const PixelSlices& slices = pixelSlices_[object];
    const shared::SliceBlend blend = shared::sliceBlendAt(static_cast<float>(in.rotation.thetaOut),
                                                          static_cast<shared::uint>(slices.thetaSamples()),
                                                          options_.interpolateSlices ? 1u : 0u);
    const LobePath lobe{&prepared_.lobeLight, p.lobes, o.toLight, p.lobeCore};
    // The sky other objects hide from it (point_lights.h), packed as the
    // Vulkan backend reads it: only where the sample sums its own (a sum
    // taken from its neighbours is theirs less their hidden sky, FusedSum).
    std::optional<std::array<float, 3>> hiddenSky;
    if (occluders.objectSky && !(sum && sum->given))
      hiddenSky = hiddenIrradiance(hiddenLightOf(objectSkyHidden(rays, point, object, occluders), frames.rotations[object]));
    rgb = fusedShade(slices, blend, in.rotation.euler, o.fusedLight, vis, o.pointLights, seen, scratch,
                     p.lobePath ? &lobe : nullptr, hiddenSky ? &*hiddenSky : nullptr, sum);
    const bool summed = !(sum && sum->given);
    return Shaded{summed ? fusedPixelBytes(slices.level(), blend.weight != 0.0f, 3 * p.visibilityBits.wordsPerPoint() * sizeof(std::uint32_t))
                         : 0,
                  scratch.passDirections, true};
  };
  std::size_t bytes = 0;
  const std::vector<std::uint8_t>& centreState = slotRecords.centreState;
  if (options_.smoothSumTolerance > 0.0f) {
    bytes += shadeSmoothSums(g, slotRecords, shadeSample, count, frame.smoothSamples, cancelPoint);
    markPart("sums from neighbours");
  } else {
    slotRecords.centreState.clear();
  }
  bytes += shadePixels(g, request, camera, frame, [&](const Sample& sample, std::size_t slot, std::array<float, 3>& rgb) {
    if (slot < centreState.size() && centreState[slot] != kNotVisited) {
      rgb = slotRecords.shaded[slot];  // shaded in shadeSmoothSums, and counted there
      return std::size_t{0};
    }
    const Shaded s = shadeSample(sample, slot, rgb, nullptr);
    if (s.pass) count(s.directions);
    return s.bytes;
  }, cancelPoint);
  markPart("rest");
  frame.stages.push_back({"fused", since(t0)});
  frame.passSamples = passSamples.load();
  frame.passDirections = passDirections.load();
  frame.passDirectionsMax = passDirectionsMax.load();
  return bytes;
}

std::size_t CpuRenderer::shadeSmoothSums(const GBuffer& g, FusedSlots& slots, const ShadeFusedSample& shade,
                                         const std::function<void(std::size_t)>& count, std::size_t& smoothSamples,
                                         const CancelPoint& cancelPoint) const {
  const int w = static_cast<int>(g.width), h = static_cast<int>(g.height);
  const std::size_t pixels = g.centre.size();
  slots.sums.resize(pixels);
  slots.shaded.resize(pixels);
  slots.mirrors.resize(pixels);
  std::vector<std::uint8_t>& state = slots.centreState;
  state.assign(pixels, kNotVisited);
  // A pixel whose sum the pass computes: an interior pixel's centre on an
  // object the pass sums (not the ground, not the lobe path alone), as
  // fused.comp's smoothVisited; once, row by row.
  HC_CHECK_LT(prepared_.objects.size(), std::size_t{std::numeric_limits<std::int16_t>::max()});
  std::vector<std::int16_t>& objectAt = slots.visitObject;
  objectAt.resize(pixels);
  parallelFor(g.height, [&](std::size_t y) {
    for (std::size_t i = y * g.width; i < (y + 1) * g.width; ++i) {
      objectAt[i] = -1;
      if (g.edge[i] != kInterior || !g.centre[i]) continue;
      const std::size_t object = g.centre[i]->hit.object;
      const PreparedObject& p = prepared_.objects[object];
      if (p.ground || (p.lobePath && p.lobeCore >= static_cast<float>(kPi))) continue;
      objectAt[i] = static_cast<std::int16_t>(object);
    }
  }, {}, options_.threads);
  const float tolerance = options_.smoothSumTolerance;
  // Each object's limit between mirror directions, once (as scene_upload.cpp puts it in ObjectInfo).
  std::vector<float> cosLimits;
  for (const PreparedObject& p : prepared_.objects) cosLimits.push_back(shared::smoothMirrorCos(p.sharpestLobe));
  std::atomic<std::size_t> bytes{0}, taken{0};
  std::vector<int> rows;
  for (shared::uint stage = 0; stage < shared::kSmoothSumStages; ++stage) {
    // The rows with pixels of this stage, in parallel; in each only its pixels.
    rows.clear();
    for (int y = 0; y < h; ++y) {
      int stride = 0;
      if (shared::smoothRowFirst(stage, y, stride) >= 0) rows.push_back(y);
    }
    parallelFor(rows.size(), [&](std::size_t r) {
      cancelPoint();
      const int y = rows[r];
      int stride = 0;
      const int first = shared::smoothRowFirst(stage, y, stride);
      std::size_t rowBytes = 0, rowTaken = 0;
      for (int x = first; x < w; x += stride) {
        shared::SmoothParents parents = shared::smoothParents(stage, x, y, w, h);
        HC_CHECK_NE(parents.count, -2);  // smoothRowFirst visits the stage's pixels only
        const std::size_t i = static_cast<std::size_t>(y) * g.width + static_cast<std::size_t>(x);
        if (objectAt[i] < 0) continue;
        const std::size_t object = static_cast<std::size_t>(objectAt[i]);
        const RotationInput& in = g.centre[i]->input.rotation;
        slots.mirrors[i] = shared::smoothMirror(static_cast<float>(in.euler.alpha), static_cast<float>(in.euler.beta),
                                                static_cast<float>(in.euler.gamma), static_cast<float>(in.thetaOut));
        // Its parents, where each is on this object, visited, and its
        // mirror direction near the pixel's; the outer ones (which only
        // measure the curve) where each is on this object and visited,
        // else dropped, and the near ones decide alone.
        const std::array<shared::uint, 8> at{parents.at0, parents.at1, parents.at2, parents.at3,
                                             parents.at4, parents.at5, parents.at6, parents.at7};
        const float cosLimit = cosLimits[object];
        auto usable = [&](shared::uint q, float limit) {
          return state[q] != kNotVisited && objectAt[q] == objectAt[i] &&
                 shared::smoothMirrorNear(slots.mirrors[i], slots.mirrors[q], limit);
        };
        bool fromParents = parents.count > 0;
        const std::size_t near = parents.count == 4 ? 4 : 2;  // then as many outer ones
        for (std::size_t k = 0; k < near && fromParents; ++k) fromParents = usable(at[k], cosLimit);
        for (std::size_t k = near; k < 2 * near && fromParents && parents.outer != 0u; ++k)
          if (!usable(at[k], -2.0f)) parents.outer = 0u;
        FusedSum sum;
        if (fromParents) {
          std::array<glm::vec3, 8> sums{};
          std::array<glm::vec3, 4> shown{};
          for (std::size_t k = 0; k < (parents.outer != 0u ? 2 * near : near); ++k)
            sums[k] = glm::vec3(slots.sums[at[k]][0], slots.sums[at[k]][1], slots.sums[at[k]][2]);
          for (std::size_t k = 0; k < near; ++k)
            shown[k] = glm::vec3(slots.shaded[at[k]][0], slots.shaded[at[k]][1], slots.shaded[at[k]][2]);
          const float brightness = shared::smoothBrightness(parents, shown[0], shown[1], shown[2], shown[3]);
          if (shared::smoothSumsAgree(parents, sums[0], sums[1], sums[2], sums[3], sums[4], sums[5], sums[6], sums[7],
                                      brightness, tolerance)) {
            const glm::vec3 mean = shared::smoothParentsSum(parents, sums[0], sums[1], sums[2], sums[3]);
            sum = {{mean.x, mean.y, mean.z}, true};
            shade(*g.centre[i], i, slots.shaded[i], &sum);
            slots.sums[i] = sum.value;
            state[i] = kTaken;
            count(0);
            ++rowTaken;
            continue;
          }
        }
        const Shaded s = shade(*g.centre[i], i, slots.shaded[i], &sum);
        slots.sums[i] = sum.value;
        state[i] = kSummed;
        count(s.directions);
        rowBytes += s.bytes;
      }
      bytes.fetch_add(rowBytes, std::memory_order_relaxed);
      taken.fetch_add(rowTaken, std::memory_order_relaxed);
    }, {}, options_.threads);
  }
  smoothSamples = taken.load();
  return bytes.load();
}

std::size_t CpuRenderer::shadeSplitsum(const ResolvedFrame& resolved, const RayScene& rays, const GBuffer& g,
                                       const FrameRequest& request, const CameraRays& camera, Frame& frame,
                                       const CancelPoint& cancelPoint) const {
  const auto t0 = Clock::now();
  const ObjectFrames frames(resolved);
  const glm::vec3 eye(camera.origin());
  const std::size_t bytes = shadePixels(g, request, camera, frame, [&](const Sample& sample, std::size_t /*slot*/, std::array<float, 3>& rgb) {
    const std::size_t object = sample.hit.object;
    const PreparedObject& p = prepared_.objects[object];
    const ResolvedObject& o = resolved.objects[object];
    const PixelInput& in = sample.input;
    // The one shadow ray along the mirror direction, against the whole posed
    // scene, as `fused`'s lobe path casts it (point_lights.h lobeRayBit).
    const ShadingPoint point = samplePoint(frames, resolved, object, in);
    const std::uint32_t seen = lobeRayBit(rays, point, eye);
    const shared::SliceBlend blend = shared::sliceBlendAt(static_cast<float>(in.rotation.thetaOut),
                                                          static_cast<shared::uint>(p.lobes.size()),
                                                          options_.interpolateSlices ? 1u : 0u);
    const LobePath path{&prepared_.lobeLight, p.lobes, o.toLight};
    rgb = splitsumShade(path, blend, in.rotation.euler, in.rotation.thetaOut, seen);
    return splitsumPixelBytes();
  }, cancelPoint);
  frame.stages.push_back({"splitsum", since(t0)});
  return bytes;
}

}  // namespace

std::unique_ptr<Renderer> makeCpuRenderer(const Scene& scene, const RenderOptions& options, const RenderProgress& progress) {
  return std::make_unique<CpuRenderer>(scene, options, progress);
}

// The one-frame convenience of step 2, now a CPU renderer used once.
RenderResult renderCpu(const Scene& scene, const RenderOptions& options, const RenderProgress& progress) {
  const auto t0 = Clock::now();
  const auto renderer = makeCpuRenderer(scene, options, progress);
  RenderResult result;
  result.timings.precompute = since(t0);
  FrameRequest request;
  request.width = options.width;
  request.height = options.height;
  request.camera = scene.camera;
  Frame frame = renderer->render(request);
  for (const StageTime& s : frame.stages) {
    if (s.name == "light") {
      result.timings.light = s.seconds;
    } else if (s.name == "gbuffer") {
      result.timings.gbuffer = s.seconds;
    } else {
      result.timings.shading += s.seconds;
    }
  }
  result.image = std::move(frame.image);
  result.objectMask = std::move(frame.objectMask);
  return result;
}

}  // namespace haarcast::render
