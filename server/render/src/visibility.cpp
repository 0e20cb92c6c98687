// Per-vertex visibility maps: Embree ray casts, pixel means by core's
// supersampledMap, forward Haar, keepLargest.
#include "haarcast/render/visibility.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/check.h"
#include "haarcast/core/parallel.h"

namespace haarcast {
namespace {

constexpr int kMaxSupersampling = 64;  // supersampledMap's own bound

// The directions visibilityMap traces: core's supersampledDirections, as
// the floats a ray takes. Computed once per call of the public functions,
// not per vertex.
std::vector<glm::vec3> sampleDirections(int level, int supersampling) {
  const std::vector<glm::dvec3> exact = supersampledDirections(level, supersampling);
  return std::vector<glm::vec3>(exact.begin(), exact.end());
}

// V at one point: each pixel the solid-angle mean over its s×s stratified
// directions (`directions` = sampleDirections(level, s)), by core's
// supersampledMap taken in its two steps, so that a visibility pixel means
// what a BRDF-slice pixel means, to the bit. The rays go to Embree 16 at a
// time (RayScene::occludedFrom; in supersampledDirections' order a packet
// at s = 2 is 4 neighbouring pixels' samples) instead of one rtcOccluded1
// each: the same
// rays and answers in under half the time (the bunny's level-6 lists, one
// thread; still 1.9× faster than single rays with Embree held to AVX2). An
// Embree stream (RayScene::occludedBatch) had been measured no faster than
// single rays: it is the explicit packets that pay.
SphereMap visibilityMap(const RayScene& occluders, const glm::vec3& origin, float tnear, int level,
                        int supersampling, std::span<const glm::vec3> directions) {
  // Per worker thread, kept across vertices.
  thread_local std::vector<std::uint8_t> blocked;
  thread_local std::vector<double> values;
  blocked.resize(directions.size());
  occluders.occludedFrom(origin, tnear, directions, blocked);
  values.resize(directions.size());
  for (std::size_t i = 0; i < directions.size(); ++i) values[i] = blocked[i] ? 0.0 : 1.0;
  return supersampledMeans(level, supersampling, values);
}

// A level's pixels in 4×4 blocks (blocks in raster order, raster order
// within each): the order in which the bits trace their directions, so that
// a packet of 16 is a compact patch of the sphere rather than a run along a
// row, and a packet that the below-horizon skip leaves short still is.
std::vector<std::uint32_t> blockOrder(int m) {
  constexpr int kBlock = 4;
  std::vector<std::uint32_t> order;
  order.reserve(static_cast<std::size_t>(m) * static_cast<std::size_t>(m));
  for (int r0 = 0; r0 < m; r0 += kBlock)
    for (int c0 = 0; c0 < m; c0 += kBlock)
      for (int r = r0; r < std::min(r0 + kBlock, m); ++r)
        for (int c = c0; c < std::min(c0 + kBlock, m); ++c) order.push_back(static_cast<std::uint32_t>(r * m + c));
  return order;
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
  const std::vector<glm::vec3> directions = sampleDirections(options.level, options.supersampling);
  parallelFor(
      total,
      [&](std::size_t v) {
        const RayStart start = rayStart(mesh, v, shift);
        out[v] = keepLargest(forwardHaar(visibilityMap(occluders, start.origin, start.tnear, options.level,
                                                       options.supersampling, directions)),
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
  // Pixel order[i]'s centre, the pixels in 4×4 blocks (blockOrder).
  const std::vector<std::uint32_t> order = blockOrder(m);
  std::vector<glm::vec3> directions(n);
  for (std::size_t i = 0; i < n; ++i) {
    const int row = static_cast<int>(order[i]) / m, col = static_cast<int>(order[i]) % m;
    directions[i] = glm::vec3(sphericalToDirection(rowTheta(level, row), colPhi(level, col)));
  }
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
        // The directions kept, without a branch per direction: each is
        // written, and the count moves past it only if it is kept.
        traced.resize(n);
        which.resize(n);
        blocked.resize(n);
        std::size_t kept = 0;
        for (std::size_t i = 0; i < n; ++i) {
          traced[kept] = directions[i];
          which[kept] = order[i];
          kept += len > 0.0f && glm::dot(directions[i], unit) < skipBelow ? 0 : 1;
        }
        occluders.occludedFrom(start.origin, start.tnear, std::span(traced).first(kept),
                               std::span(blocked).first(kept));
        const std::span<std::uint32_t> words = out.point(v);
        std::fill(words.begin(), words.end(), 0u);
        for (std::size_t t = 0; t < kept; ++t)
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
  return visibilityMap(occluders, start.origin, start.tnear, options.level, options.supersampling,
                       sampleDirections(options.level, options.supersampling));
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
  return visibilityMap(occluders, origin, tnear, level, supersampling, sampleDirections(level, supersampling));
}

}  // namespace haarcast
