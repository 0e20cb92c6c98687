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
  const unsigned threads = options.threads;  // 0 = all cores (parallelFor)
  const int level = options.level;
  RenderResult result;

  // ---- Once per object --------------------------------------------------
  auto t0 = Clock::now();
  std::vector<PreparedObject> objects(scene.objects.size());
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    PreparedObject& p = objects[k];
    p.object = &scene.objects[k];
    p.object->mesh->validate();
    p.mesh = withNormals(p.object->mesh);  // a mesh built in code may come without them
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
  const CameraRays camera(scene.camera, w, h);
  std::vector<std::optional<Hit>> hits(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  parallelFor(static_cast<std::size_t>(h), [&](std::size_t y) {
    for (int x = 0; x < w; ++x) {
      Ray r;
      r.origin = glm::vec3(camera.origin());
      r.direction = glm::vec3(camera.direction(x, static_cast<int>(y)));
      hits[y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] = rays.intersect(r);
    }
  }, {}, threads);
  result.timings.gbuffer = since(t0);

  // ---- Per pixel: rotation and triple product ------------------------------
  t0 = Clock::now();
  result.image = io::makeImage(w, h);
  result.objectMask.assign(hits.size(), 0);
  parallelFor(static_cast<std::size_t>(h), [&](std::size_t y) {
    HaarMap rotated;
    for (int x = 0; x < w; ++x) {
      const std::size_t i = y * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      const glm::dvec3 dir = camera.direction(x, static_cast<int>(y));
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
  }, [&](std::size_t rows) {
    if (progress) progress("shading", rows, static_cast<std::size_t>(h));
  }, threads);
  result.timings.shading = since(t0);
  return result;
}

}  // namespace haarcast::render
