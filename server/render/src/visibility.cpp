// Per-vertex visibility maps: Embree ray casts, pixel means by core's
// supersampledMap, forward Haar, keepLargest.
#include "haarcast/render/visibility.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/check.h"
#include "haarcast/core/parallel.h"

namespace haarcast {
namespace {

constexpr int kMaxSupersampling = 64;  // supersampledMap's own bound

// V at one point: each pixel the solid-angle mean over its s×s stratified
// directions, by core's supersampledMap, so that a visibility pixel means what
// a BRDF-slice pixel means. One rtcOccluded1 per direction: tracing a vertex's
// directions as one coherent Embree stream (RayScene::occludedBatch, shared
// origin, raster order) was measured no faster on the bunny (within ±10% of
// single rays, 2-core AVX2 box), so the simpler path stays.
SphereMap visibilityMap(const RayScene& occluders, const glm::vec3& origin, float tnear, int level,
                        int supersampling) {
  return supersampledMap(level, supersampling, [&](const glm::dvec3& d) {
    return occluders.occluded(Ray{origin, glm::vec3(d), tnear}) ? 0.0 : 1.0;
  });
}

// Where a vertex's rays start: the vertex moved along its unit normal, or,
// without a usable normal, the vertex itself with the offset as tnear.
struct RayStart {
  glm::vec3 origin;
  float tnear;
};

RayStart rayStart(const Mesh& mesh, std::size_t vertex, float shift) {
  const glm::vec3 p = mesh.positions[vertex];
  const glm::vec3 n = mesh.normals[vertex];
  const float len = glm::length(n);
  if (!(len > 0.0f) || !std::isfinite(len)) return {p, shift};
  return {p + n * (shift / len), 0.0f};
}

float shiftOf(const Mesh& mesh, const VisibilityOptions& options) {
  return static_cast<float>(options.offset * mesh.bounds().radius());
}

void checkMeshForVisibility(const Mesh& mesh) {
  mesh.validate();
  if (mesh.normals.size() != mesh.positions.size()) {
    throw std::invalid_argument("visibility: mesh \"" + mesh.name + "\" has no normals");
  }
}


// compute(scene, mesh) with the mesh alone as the occluders; a mesh without
// normals gets area-weighted ones (Mesh::computeNormals) on a copy first.
template <typename Compute>
auto againstItself(const Mesh& mesh, Compute&& compute) {
  mesh.validate();
  if (mesh.normals.empty()) {
    Mesh withNormals = mesh;
    withNormals.computeNormals();
    const RayScene scene({Instance{&withNormals}});
    return compute(scene, withNormals);
  }
  const RayScene scene({Instance{&mesh}});
  return compute(scene, mesh);
}

}  // namespace

void checkVisibilityOptions(const VisibilityOptions& options) {
  checkLevel(options.level, "visibility");
  if (options.supersampling < 1 || options.supersampling > kMaxSupersampling) {
    throw std::invalid_argument("visibility: supersampling " + std::to_string(options.supersampling) +
                                " is outside [1, " + std::to_string(kMaxSupersampling) + "]");
  }
  if (options.keep == 0) throw std::invalid_argument("visibility: keep must be at least 1 coefficient");
  if (!std::isfinite(options.offset) || options.offset < 0.0f) {
    throw std::invalid_argument("visibility: offset " + std::to_string(options.offset) +
                                " must be finite and non-negative");
  }
}

std::vector<SparseHaar> computeVertexVisibility(
    const Mesh& mesh, const VisibilityOptions& options,
    const std::function<void(std::size_t done, std::size_t total)>& progress) {
  checkVisibilityOptions(options);
  return againstItself(mesh, [&](const RayScene& scene, const Mesh& m) {
    return computeVertexVisibility(scene, m, options, progress);
  });
}

std::vector<SparseHaar> computeVertexVisibility(
    const RayScene& occluders, const Mesh& mesh, const VisibilityOptions& options,
    const std::function<void(std::size_t done, std::size_t total)>& progress) {
  checkVisibilityOptions(options);
  checkMeshForVisibility(mesh);
  const float shift = shiftOf(mesh, options);
  std::vector<SparseHaar> out(mesh.positions.size());
  const std::size_t total = mesh.positions.size();
  parallelFor(
      total,
      [&](std::size_t v) {
        const RayStart start = rayStart(mesh, v, shift);
        out[v] = keepLargest(
            forwardHaar(visibilityMap(occluders, start.origin, start.tnear, options.level, options.supersampling)),
            options.keep);
      },
      [&](std::size_t done) {
        if (progress) progress(done, total);
      });
  return out;
}

VisibilityBits computeVisibilityBits(const Mesh& mesh, const VisibilityOptions& options,
                                     const std::function<void(std::size_t done, std::size_t total)>& progress) {
  checkVisibilityOptions(options);
  return againstItself(mesh, [&](const RayScene& scene, const Mesh& m) {
    return computeVisibilityBits(scene, m, options, progress);
  });
}

VisibilityBits computeVisibilityBits(const RayScene& occluders, const Mesh& mesh, const VisibilityOptions& options,
                                     const std::function<void(std::size_t done, std::size_t total)>& progress) {
  checkVisibilityOptions(options);
  VisibilityBits out(options.level, mesh.positions.size());
  computeVisibilityBitsFrom(occluders, mesh, options, 0, out, progress);
  return out;
}

void computeVisibilityBitsFrom(const RayScene& occluders, const Mesh& mesh, const VisibilityOptions& options,
                               std::size_t first, VisibilityBits& out,
                               const std::function<void(std::size_t done, std::size_t total)>& progress) {
  checkVisibilityOptions(options);
  checkMeshForVisibility(mesh);
  HC_CHECK_EQ(out.level(), options.level);
  HC_CHECK_EQ(out.pointCount(), mesh.positions.size());
  HC_CHECK_LE(first, mesh.positions.size());
  const int level = options.level;
  const int m = mapSize(level);
  const std::size_t n = static_cast<std::size_t>(m) * static_cast<std::size_t>(m);
  std::vector<glm::vec3> directions(n);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      directions[static_cast<std::size_t>(i * m + j)] = glm::vec3(sphericalToDirection(rowTheta(level, i), colPhi(level, j)));
  const float skipBelow = static_cast<float>(-std::sin(kBitsSkipBelowDegrees * kPi / 180.0));
  const float shift = shiftOf(mesh, options);
  const std::size_t total = mesh.positions.size() - first;
  parallelFor(
      total,
      [&](std::size_t k) {
        const std::size_t v = first + k;
        // Per worker thread, kept across vertices.
        thread_local std::vector<glm::vec3> traced;
        thread_local std::vector<std::uint32_t> which;
        thread_local std::vector<std::uint8_t> blocked;
        const RayStart start = rayStart(mesh, v, shift);
        const glm::vec3 normal = mesh.normals[v];
        const float len = glm::length(normal);
        const glm::vec3 unit = len > 0.0f && std::isfinite(len) ? normal / len : glm::vec3(0.0f);
        traced.clear();
        which.clear();
        for (std::size_t i = 0; i < n; ++i) {
          if (len > 0.0f && glm::dot(directions[i], unit) < skipBelow) continue;
          traced.push_back(directions[i]);
          which.push_back(static_cast<std::uint32_t>(i));
        }
        blocked.resize(traced.size());
        occluders.occludedFrom(start.origin, start.tnear, traced, blocked);
        const std::span<std::uint32_t> words = out.point(v);
        std::fill(words.begin(), words.end(), 0u);
        for (std::size_t t = 0; t < traced.size(); ++t)
          if (!blocked[t]) words[which[t] / 32] |= 1u << (which[t] % 32);
      },
      [&](std::size_t done) {
        if (progress) progress(done, total);
      });
}

SphereMap vertexVisibilityMap(const RayScene& occluders, const Mesh& mesh, std::size_t vertex,
                              const VisibilityOptions& options) {
  checkVisibilityOptions(options);
  checkMeshForVisibility(mesh);
  if (vertex >= mesh.positions.size()) {
    throw std::out_of_range("vertexVisibilityMap: vertex " + std::to_string(vertex) + " of " +
                            std::to_string(mesh.positions.size()));
  }
  const RayStart start = rayStart(mesh, vertex, shiftOf(mesh, options));
  return visibilityMap(occluders, start.origin, start.tnear, options.level, options.supersampling);
}

SphereMap pointVisibilityMap(const RayScene& occluders, const glm::vec3& origin, int level, int supersampling,
                             float tnear) {
  VisibilityOptions options;
  options.level = level;
  options.supersampling = supersampling;
  checkVisibilityOptions(options);
  if (!std::isfinite(tnear) || tnear < 0.0f) {
    throw std::invalid_argument("pointVisibilityMap: tnear " + std::to_string(tnear) + " must be finite and ≥ 0");
  }
  return visibilityMap(occluders, origin, tnear, level, supersampling);
}

}  // namespace haarcast
