// What both backends share (one definition of every number), and the CPU
// reference backend behind the Renderer interface.
#include "haarcast/render/renderer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include <glm/geometric.hpp>

#include "haarcast/core/parallel.h"
#include "haarcast/core/triple_product.h"
#include "haarcast/io/slice_cache.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/render/shading.h"
#include "haarcast/render/visibility_cache.h"

namespace haarcast::render {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

}  // namespace

// ---------------------------------------------------------------- shared steps

void checkRenderOptions(const RenderOptions& o) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("render options: " + what); };
  if (o.width < 1 || o.height < 1 || o.width > 8192 || o.height > 8192) {
    bad("resolution " + std::to_string(o.width) + "×" + std::to_string(o.height) + " is outside 1..8192");
  }
  if (o.level < 2 || o.level > 8) bad("level " + std::to_string(o.level) + " is outside 2..8");
  if (o.lightCoefficients == 0) bad("light coefficients must be at least 1");
  if (o.thetaSamples < 1 || o.thetaSamples > 256) bad("theta samples must be in 1..256");
}

PreparedScene prepareScene(const Scene& scene, const RenderOptions& options, const RenderProgress& progress) {
  checkRenderOptions(options);
  if (scene.objects.empty()) throw std::invalid_argument("render: the scene has no objects");
  PreparedScene prepared;
  prepared.scene = scene;
  prepared.objects.resize(scene.objects.size());
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    const SceneObject& object = scene.objects[k];
    PreparedObject& p = prepared.objects[k];
    p.name = object.name;
    p.pose = object.pose;
    object.mesh->validate();
    p.mesh = withNormals(object.mesh);  // a mesh built in code may come without them
    SliceTableOptions table;
    table.level = options.level;
    table.thetaSamples = options.thetaSamples;
    table.supersampling = options.sliceSupersampling;
    auto tableProgress = [&](int done, int total) {
      if (progress) progress("slices " + object.name, static_cast<std::size_t>(done), static_cast<std::size_t>(total));
    };
    p.table = options.cacheDir.empty()
                  ? BrdfSliceTable::build(*object.material.brdf, table, tableProgress)
                  : io::loadOrBuildSliceTable(*object.material.brdf, table, options.cacheDir,
                                              object.material.cacheKey, tableProgress);
    VisibilityOptions vis = options.visibility;
    vis.level = options.level;
    p.visibility = loadOrComputeVertexVisibility(*p.mesh, vis, options.cacheDir, [&](std::size_t done, std::size_t total) {
      if (progress) progress("visibility " + object.name, done, total);
    });
  }
  prepared.light = scene.environment.maps(options.level);
  prepared.background = scene.environment.maps(kBackgroundLevel);
  return prepared;
}

std::array<SparseHaar, 3> lightInObjectFrame(const std::array<SphereMap, 3>& worldLight, const glm::dmat3& objectRotation,
                                             const glm::dmat3& lightRotation, std::size_t k) {
  // L_obj(ω) = L(Mω) with M = lightRotationᵀ·objectRotation; rotating a map
  // by E gives g(ω) = f(Eᵀω), so E = Mᵀ.
  const EulerYXY toObject = eulerFromMatrix(glm::transpose(glm::transpose(lightRotation) * objectRotation));
  std::array<SparseHaar, 3> light;
  for (std::size_t c = 0; c < 3; ++c) {
    const SphereMap local = rotateSpatialMap(worldLight[c], toObject);
    light[c] = keepLargest(forwardHaar(local.weightedBySolidAngle()), k);
  }
  return light;
}

RotationInput rotationInput(const glm::dvec3& normal, const glm::dvec3& towardEye, const BrdfSliceTable& table) {
  double thetaOut = 0.0;
  RotationInput in;
  in.euler = eulerFromMatrix(shadingFrame(normal, towardEye, thetaOut));
  in.slice = table.nearestSlice(thetaOut);
  return in;
}

glm::dvec3 backgroundRadiance(const std::array<SphereMap, 3>& background, const glm::dmat3& lightRotation,
                              const glm::dvec3& direction) {
  // L'(ω) = L(Rᵀω).
  const Spherical s = directionToSpherical(glm::transpose(lightRotation) * direction);
  const int level = background[0].level();
  const BilinearTaps taps = bilinearTaps(level, s.theta, s.phi);
  glm::dvec3 out(0.0);
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      const double w = taps.weight(a, b);
      for (int c = 0; c < 3; ++c) {
        out[c] += w * background[static_cast<std::size_t>(c)].at(taps.row[static_cast<std::size_t>(a)],
                                                                  taps.col[static_cast<std::size_t>(b)]);
      }
    }
  }
  return out;
}

std::vector<std::uint8_t> tonemapRgba8(const io::RgbImage& image, double exposureStops) {
  const double gain = std::exp2(exposureStops);
  const std::size_t pixels = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  std::vector<std::uint8_t> out(pixels * 4);
  for (std::size_t p = 0; p < pixels; ++p) {
    for (std::size_t c = 0; c < 3; ++c) out[4 * p + c] = io::encodeSrgb(image.rgb[3 * p + c] * gain);
    out[4 * p + 3] = 255;
  }
  return out;
}

void checkFrameRequest(const FrameRequest& r, std::size_t objectCount) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("frame request: " + what); };
  if (r.width < 1 || r.height < 1 || r.width > 8192 || r.height > 8192) {
    bad("resolution " + std::to_string(r.width) + "×" + std::to_string(r.height) + " is outside 1..8192");
  }
  if (!r.poses.empty() && r.poses.size() != objectCount) {
    bad(std::to_string(r.poses.size()) + " poses for " + std::to_string(objectCount) + " objects");
  }
  if (!(r.camera.fovYDegrees > 0.0 && r.camera.fovYDegrees < 180.0)) {
    bad("camera fov " + std::to_string(r.camera.fovYDegrees) + "° is outside (0, 180)");
  }
  const glm::dvec3 view = r.camera.target - r.camera.eye;
  if (!(glm::length(view) > 1e-12) || !(glm::length(glm::cross(view, r.camera.up)) > 1e-12 * glm::length(view))) {
    bad("camera eye, target and up must be finite, distinct and not collinear");
  }
  for (const Pose& p : r.poses) {
    if (!std::isfinite(p.rotateDegrees.x + p.rotateDegrees.y + p.rotateDegrees.z + p.translate.x + p.translate.y +
                       p.translate.z) ||
        !(p.scale > 0.0 && std::isfinite(p.scale))) {
      bad("a pose is not finite (or its scale is not positive)");
    }
  }
  if (!std::isfinite(r.exposureStops)) bad("exposure is not finite");
}

// ---------------------------------------------------------------- CPU backend

namespace {

class CpuRenderer final : public Renderer {
 public:
  CpuRenderer(const Scene& scene, const RenderOptions& options, const RenderProgress& progress)
      : options_(options), prepared_(prepareScene(scene, options, progress)) {
    for (const PreparedObject& p : prepared_.objects) {
      std::array<std::unique_ptr<SliceRotator>, 3> r;
      for (int c = 0; c < 3; ++c) r[static_cast<std::size_t>(c)] = makeRotator(options.method, p.table.channelSlices(c), options.rotator);
      rotators_.push_back(std::move(r));
    }
    // The meshes' ray structures are built once; frames only move them.
    std::vector<Instance> instances;
    for (const PreparedObject& p : prepared_.objects) instances.push_back({p.mesh.get(), glm::mat4(p.pose.objectToWorld())});
    rays_ = std::make_unique<RayScene>(std::move(instances));
  }

  std::string backend() const override { return "cpu"; }
  std::string deviceName() const override { return "cpu reference (" + std::to_string(hardwareThreads(options_.threads)) + " threads)"; }
  const RenderOptions& options() const override { return options_; }
  std::size_t objectCount() const override { return prepared_.objects.size(); }

  Frame render(const FrameRequest& request) override;

 private:
  static unsigned hardwareThreads(unsigned t) { return t ? t : std::max(1u, std::thread::hardware_concurrency()); }
  // Bytes one rotation of one channel reads: the slice, plus for `matrix`
  // the two elevation matrices it blends and for `table` the stored copy
  // (which replaces the slice).
  std::size_t rotationBytes(std::size_t object) const;

  RenderOptions options_;
  PreparedScene prepared_;
  std::vector<std::array<std::unique_ptr<SliceRotator>, 3>> rotators_;
  std::unique_ptr<RayScene> rays_;  // posed per frame with setTransform (top level only)
};

std::size_t CpuRenderer::rotationBytes(std::size_t object) const {
  const std::size_t slice = static_cast<std::size_t>(mapSize(options_.level)) * static_cast<std::size_t>(mapSize(options_.level)) * sizeof(float);
  if (options_.method != RotationMethod::Matrix) return slice;
  const SliceRotator& r = *rotators_[object][0];
  const std::size_t matrices = r.storedBytes() - slice * r.sliceCount();
  return slice + 2 * matrices / static_cast<std::size_t>(std::max(1, options_.rotator.matrixElevations));
}

Frame CpuRenderer::render(const FrameRequest& request) {
  checkFrameRequest(request, prepared_.objects.size());
  const auto start = Clock::now();
  const unsigned threads = options_.threads;
  const std::size_t k = request.lightCoefficients ? request.lightCoefficients : options_.lightCoefficients;
  const std::vector<Pose>& poses = request.poses;
  auto poseOf = [&](std::size_t i) -> const Pose& { return poses.empty() ? prepared_.objects[i].pose : poses[i]; };
  Frame frame;
  std::size_t bytes = 0;

  // ---- light: world → each object's frame, once per frame -----------------
  auto t0 = Clock::now();
  std::vector<std::array<SparseHaar, 3>> light(prepared_.objects.size());
  std::vector<glm::dmat3> rotation(prepared_.objects.size());
  for (std::size_t i = 0; i < light.size(); ++i) {
    rotation[i] = poseOf(i).rotation();
    light[i] = lightInObjectFrame(prepared_.light, rotation[i], request.lightRotation, k);
    for (const SparseHaar& s : light[i]) bytes += s.size() * (sizeof(std::uint32_t) + sizeof(float));
  }
  frame.stages.push_back({"light", since(t0)});

  // ---- gbuffer: Embree primary rays at pixel centres ----------------------
  t0 = Clock::now();
  for (std::size_t i = 0; i < prepared_.objects.size(); ++i) rays_->setTransform(i, glm::mat4(poseOf(i).objectToWorld()));
  const RayScene& rays = *rays_;
  const int w = request.width, h = request.height;
  const CameraRays camera(request.camera, w, h);
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  std::vector<std::optional<Hit>> hits(pixels);
  parallelFor(static_cast<std::size_t>(h), [&](std::size_t y) {
    for (int x = 0; x < w; ++x) {
      Ray r;
      r.origin = glm::vec3(camera.origin());
      r.direction = glm::vec3(camera.direction(x, static_cast<int>(y)));
      hits[y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] = rays.intersect(r);
    }
  }, {}, threads);
  frame.stages.push_back({"gbuffer", since(t0)});

  // ---- rotation-input: slice and Euler angles per covered pixel -----------
  t0 = Clock::now();
  struct PixelInput {
    RotationInput rotation;
    double b[3];
    unsigned vertex[3];
  };
  std::vector<PixelInput> inputs(pixels);
  parallelFor(static_cast<std::size_t>(h), [&](std::size_t y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      if (!hits[i]) continue;
      const Hit& hit = *hits[i];
      const PreparedObject& p = prepared_.objects[hit.object];
      const Mesh& mesh = *p.mesh;
      const glm::uvec3 tri = mesh.triangles[hit.triangle];
      PixelInput& in = inputs[i];
      in.b[0] = 1.0 - hit.u - hit.v;
      in.b[1] = hit.u;
      in.b[2] = hit.v;
      in.vertex[0] = tri.x;
      in.vertex[1] = tri.y;
      in.vertex[2] = tri.z;
      const glm::dvec3 n = glm::normalize(in.b[0] * glm::dvec3(mesh.normals[tri.x]) + in.b[1] * glm::dvec3(mesh.normals[tri.y]) +
                                          in.b[2] * glm::dvec3(mesh.normals[tri.z]));
      const glm::dvec3 wo = glm::transpose(rotation[hit.object]) * -camera.direction(x, static_cast<int>(y));  // object frame
      in.rotation = rotationInput(n, wo, p.table);
    }
  }, {}, threads);
  frame.stages.push_back({"rotation-input", since(t0)});

  // ---- rotation + triple product, fused per pixel -------------------------
  // The CPU keeps one rotated map per thread instead of a frame's worth, so
  // the two stages run interleaved; their wall time is split in proportion
  // to the thread time each took.
  t0 = Clock::now();
  frame.image = io::makeImage(w, h);
  frame.objectMask.assign(pixels, 0);
  std::atomic<std::int64_t> rotationNs{0}, productNs{0};
  std::atomic<std::size_t> shadingBytes{0};
  parallelFor(static_cast<std::size_t>(h), [&](std::size_t y) {
    HaarMap rotated;
    std::int64_t rot = 0, prod = 0;
    std::size_t rowBytes = 0;
    for (int x = 0; x < w; ++x) {
      const std::size_t i = y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      if (!hits[i]) continue;
      frame.objectMask[i] = 1;
      const std::size_t object = hits[i]->object;
      const PreparedObject& p = prepared_.objects[object];
      const PixelInput& in = inputs[i];
      for (std::size_t c = 0; c < 3; ++c) {
        const auto a = Clock::now();
        rotators_[object][c]->rotate(static_cast<std::size_t>(in.rotation.slice), in.rotation.euler, rotated);
        const auto b = Clock::now();
        double sum = 0.0;
        // The visibility blend is linear, so it distributes over the product.
        for (int v = 0; v < 3; ++v) {
          const SparseHaar& vis = p.visibility[in.vertex[v]];
          sum += in.b[v] * tripleProduct(light[object][c], rotated, vis);
          rowBytes += vis.size() * (sizeof(std::uint32_t) + sizeof(float));
        }
        rot += std::chrono::duration_cast<std::chrono::nanoseconds>(b - a).count();
        prod += std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - b).count();
        rowBytes += rotationBytes(object);
        frame.image.at(static_cast<int>(y), x, static_cast<int>(c)) = static_cast<float>(sum);
      }
    }
    rotationNs += rot;
    productNs += prod;
    shadingBytes += rowBytes;
  }, {}, threads);
  const double shading = since(t0);
  const double busy = static_cast<double>(rotationNs.load() + productNs.load());
  const double rotationShare = busy > 0.0 ? static_cast<double>(rotationNs.load()) / busy : 0.5;
  frame.stages.push_back({"rotation", shading * rotationShare});
  frame.stages.push_back({"triple-product", shading * (1.0 - rotationShare)});
  bytes += shadingBytes.load();

  // ---- tonemap: backdrop, RGBA8 --------------------------------------------
  t0 = Clock::now();
  if (options_.environmentBackground) {
    parallelFor(static_cast<std::size_t>(h), [&](std::size_t y) {
      for (int x = 0; x < w; ++x) {
        if (frame.objectMask[y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)]) continue;
        const glm::dvec3 L = backgroundRadiance(prepared_.background, request.lightRotation, camera.direction(x, static_cast<int>(y)));
        for (int c = 0; c < 3; ++c) frame.image.at(static_cast<int>(y), x, c) = static_cast<float>(L[c]);
      }
    }, {}, threads);
  }
  frame.rgba8 = tonemapRgba8(frame.image, request.exposureStops);
  frame.stages.push_back({"tonemap", since(t0)});
  frame.coefficientBytes = bytes;
  frame.seconds = since(start);
  return frame;
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
