#include "haarcast/render/cpu_renderer.h"

#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/triple_product.h"
#include "haarcast/io/slice_cache.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/render/visibility_cache.h"

namespace haarcast::render {
namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Runs body(i) for i in [0, count) on `threads` threads; the calling thread
// reports progress. The first exception is rethrown after all threads stop.
void parallelFor(std::size_t count, unsigned threads, const std::function<void(std::size_t)>& body,
                 const std::function<void(std::size_t)>& onProgress) {
  std::atomic<std::size_t> next{0}, done{0};
  std::exception_ptr error;
  std::atomic<bool> failed{false};
  auto work = [&] {
    for (std::size_t i; !failed && (i = next++) < count;) {
      try {
        body(i);
      } catch (...) {
        if (!failed.exchange(true)) error = std::current_exception();
      }
      ++done;
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (error) std::rethrow_exception(error);
  if (onProgress) onProgress(done);
}

// Everything precomputed for one object.
struct PreparedObject {
  const SceneObject* object = nullptr;
  std::shared_ptr<const Mesh> mesh;    // the object's, with normals
  BrdfSliceTable table;
  std::array<std::unique_ptr<SliceRotator>, 3> rotators;
  std::vector<SparseHaar> visibility;  // per vertex, object frame
  std::array<SparseHaar, 3> light;     // this frame's light in the object frame
  glm::dmat3 rotation{1.0};            // object → world
};

// The local shading frame as a rotation local → object: +Y = n, the view
// direction in the (Y, Z) half-plane at φ = 0 (DESIGN.md "BRDF slices").
glm::dmat3 shadingFrame(const glm::dvec3& n, const glm::dvec3& wo, double& thetaOut) {
  const double c = std::clamp(glm::dot(n, wo), -1.0, 1.0);
  thetaOut = std::acos(std::max(c, 0.0));
  glm::dvec3 z = wo - c * n;
  if (glm::dot(z, z) < 1e-16) {  // view along the normal: any tangent will do
    z = std::abs(n.x) < 0.9 ? glm::cross(n, glm::dvec3(1, 0, 0)) : glm::cross(n, glm::dvec3(0, 1, 0));
  }
  z = glm::normalize(z);
  const glm::dvec3 x = glm::cross(n, z);  // right-handed: x = y × z
  return glm::dmat3(x, n, z);
}

}  // namespace

void checkRenderOptions(const RenderOptions& o) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("render options: " + what); };
  if (o.width < 1 || o.height < 1 || o.width > 8192 || o.height > 8192) {
    bad("resolution " + std::to_string(o.width) + "×" + std::to_string(o.height) + " is outside 1..8192");
  }
  if (o.level < 2 || o.level > 8) bad("level " + std::to_string(o.level) + " is outside 2..8");
  if (o.lightCoefficients == 0) bad("light coefficients must be at least 1");
  if (o.thetaSamples < 1 || o.thetaSamples > 256) bad("theta samples must be in 1..256");
}

RenderResult renderCpu(const Scene& scene, const RenderOptions& options, const RenderProgress& progress) {
  checkRenderOptions(options);
  if (scene.objects.empty()) throw std::invalid_argument("render: the scene has no objects");
  const unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  const int level = options.level;
  RenderResult result;

  // ---- Once per object --------------------------------------------------
  auto t0 = Clock::now();
  std::vector<PreparedObject> objects(scene.objects.size());
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    PreparedObject& p = objects[k];
    p.object = &scene.objects[k];
    p.mesh = p.object->mesh;
    p.mesh->validate();
    if (p.mesh->normals.empty()) {  // a mesh built in code may come without them
      auto withNormals = std::make_shared<Mesh>(*p.mesh);
      withNormals->computeNormals();
      p.mesh = withNormals;
    }
    SliceTableOptions table;
    table.level = level;
    table.thetaSamples = options.thetaSamples;
    table.supersampling = options.sliceSupersampling;
    auto tableProgress = [&](int done, int total) {
      if (progress) progress("slices " + p.object->name, static_cast<std::size_t>(done), static_cast<std::size_t>(total));
    };
    p.table = options.cacheDir.empty()
                  ? BrdfSliceTable::build(*p.object->material.brdf, table, tableProgress)
                  : io::loadOrBuildSliceTable(*p.object->material.brdf, table, options.cacheDir,
                                              p.object->material.cacheKey, tableProgress);
    for (int c = 0; c < 3; ++c) p.rotators[static_cast<std::size_t>(c)] = makeRotator(options.method, p.table.channelSlices(c), options.rotator);
    VisibilityOptions vis = options.visibility;
    vis.level = level;
    p.visibility = loadOrComputeVertexVisibility(*p.mesh, vis, options.cacheDir, [&](std::size_t done, std::size_t total) {
      if (progress) progress("visibility " + p.object->name, done, total);
    });
    p.rotation = p.object->pose.rotation();
  }
  result.timings.precompute = since(t0);

  // ---- Once per frame: the light in each object's frame -------------------
  t0 = Clock::now();
  const std::array<SphereMap, 3> world = scene.environment.maps(level);
  for (PreparedObject& p : objects) {
    // L_obj(ω) = L_world(R ω): rotating by Rᵀ gives g(ω) = f(R ω).
    const EulerYXY toObject = eulerFromMatrix(glm::transpose(p.rotation));
    for (int c = 0; c < 3; ++c) {
      const SphereMap local = rotateSpatialMap(world[static_cast<std::size_t>(c)], toObject);
      p.light[static_cast<std::size_t>(c)] = keepLargest(forwardHaar(local.weightedBySolidAngle()), options.lightCoefficients);
    }
  }
  result.timings.light = since(t0);

  // ---- G-buffer: primary rays ---------------------------------------------
  t0 = Clock::now();
  std::vector<Instance> instances;
  for (const PreparedObject& p : objects) instances.push_back({p.mesh.get(), glm::mat4(p.object->pose.objectToWorld())});
  const RayScene rays(std::move(instances));
  const int w = options.width, h = options.height;
  const Camera& cam = scene.camera;
  const glm::dvec3 forward = glm::normalize(cam.target - cam.eye);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, cam.up));
  const glm::dvec3 up = glm::cross(right, forward);
  const double tanHalf = std::tan(glm::radians(cam.fovYDegrees) * 0.5);
  const double aspect = static_cast<double>(w) / h;
  auto pixelRay = [&](int x, int y) {
    const double sx = (2.0 * (x + 0.5) / w - 1.0) * tanHalf * aspect;
    const double sy = (1.0 - 2.0 * (y + 0.5) / h) * tanHalf;
    return glm::normalize(forward + sx * right + sy * up);
  };
  std::vector<std::optional<Hit>> hits(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  parallelFor(static_cast<std::size_t>(h), threads, [&](std::size_t y) {
    for (int x = 0; x < w; ++x) {
      Ray r;
      r.origin = glm::vec3(cam.eye);
      r.direction = glm::vec3(pixelRay(x, static_cast<int>(y)));
      hits[y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] = rays.intersect(r);
    }
  }, {});
  result.timings.gbuffer = since(t0);

  // ---- Per pixel: rotation and triple product ------------------------------
  t0 = Clock::now();
  result.image = io::makeImage(w, h);
  result.objectMask.assign(hits.size(), 0);
  std::atomic<std::size_t> rowsDone{0};
  std::mutex progressMutex;  // shading reports from the worker threads, one at a time
  parallelFor(static_cast<std::size_t>(h), threads, [&](std::size_t y) {
    HaarMap rotated;
    for (int x = 0; x < w; ++x) {
      const std::size_t i = y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      const glm::dvec3 dir = pixelRay(x, static_cast<int>(y));
      glm::dvec3 radiance(0.0);
      if (!hits[i]) {
        if (options.environmentBackground) radiance = scene.environment.radiance(dir);
      } else {
        result.objectMask[i] = 1;
        const Hit& hit = *hits[i];
        const PreparedObject& p = objects[hit.object];
        const Mesh& mesh = *p.mesh;
        const glm::uvec3 tri = mesh.triangles[hit.triangle];
        const double b[3] = {1.0 - hit.u - hit.v, hit.u, hit.v};
        const glm::dvec3 n = glm::normalize(b[0] * glm::dvec3(mesh.normals[tri.x]) + b[1] * glm::dvec3(mesh.normals[tri.y]) +
                                            b[2] * glm::dvec3(mesh.normals[tri.z]));
        const glm::dvec3 wo = glm::transpose(p.rotation) * -dir;  // toward the eye, object frame
        double thetaOut = 0.0;
        const EulerYXY r = eulerFromMatrix(shadingFrame(n, wo, thetaOut));
        const int slice = p.table.nearestSlice(thetaOut);
        const unsigned vertex[3] = {tri.x, tri.y, tri.z};
        for (int c = 0; c < 3; ++c) {
          p.rotators[static_cast<std::size_t>(c)]->rotate(static_cast<std::size_t>(slice), r, rotated);
          double sum = 0.0;
          // The visibility blend is linear, so it distributes over the product.
          for (int v = 0; v < 3; ++v) {
            sum += b[v] * tripleProduct(p.light[static_cast<std::size_t>(c)], rotated, p.visibility[vertex[v]]);
          }
          radiance[c] = sum;
        }
      }
      for (int c = 0; c < 3; ++c) result.image.at(static_cast<int>(y), x, c) = static_cast<float>(radiance[c]);
    }
    const std::size_t done = ++rowsDone;
    if (progress) {
      const std::lock_guard<std::mutex> lock(progressMutex);
      progress("shading", done, static_cast<std::size_t>(h));
    }
  }, {});
  result.timings.shading = since(t0);
  return result;
}

}  // namespace haarcast::render
