// Per-vertex visibility in the object frame (DESIGN.md "Frames", "The path of
// a frame"): for each vertex, V(ω) = 1 if a ray from the vertex toward ω
// escapes, else 0, as a level-n lat-long map in the object's own frame,
// Haar-coded and kept to its largest coefficients. It is precomputed once per
// mesh; at run time it meets the light (rotated world→object) and the rotated
// BRDF slice in the triple product.
//
// Choices where the design is silent:
// - Each pixel holds the solid-angle mean of V over the pixel, from s×s
//   stratified directions — exactly the samples and weights of core's
//   supersampledMap (brdf_slices.h), so visibility, BRDF slices and every
//   analytic reference agree on what a pixel means.
// - The ray starts at the vertex moved along its unit normal by
//   offset·(the mesh's bounding radius), with tnear = 0. The shift keeps the
//   vertex's own triangles from shadowing its upper hemisphere; a fixed
//   fraction of the object's size makes the result independent of units.
//   So normals must face out of the object: an inward normal starts the rays
//   inside a closed surface and V ≈ 0 everywhere. (Winding decides the
//   normals Mesh::computeNormals makes; ../shared/data's bunny.ply is wound
//   inward — signed volume < 0 — while stanford-bunny.obj is wound outward.)
// - Directions below the tangent plane are traced like any other: they hit
//   the surface (V = 0) unless the surface there is thinner than the offset
//   or the direction grazes it. The BRDF·cos slice is zero there anyway, so
//   this costs rays but no accuracy, and V stays the honest ray-cast answer.
// - A vertex without a usable normal (zero or non-finite, which
//   Mesh::computeNormals never produces but a file may) is not offset: its
//   rays start at tnear = offset·radius instead.
// - Both sides of every triangle occlude (Embree has no back-face culling).
#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include <glm/vec3.hpp>

#include "haarcast/core/haar.h"
#include "haarcast/core/mesh.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/core/visibility_bits.h"
#include "haarcast/render/embree_scene.h"

namespace haarcast {

struct VisibilityOptions {
  int level = 5;           // map level n (M = 2^n); 0 ≤ n ≤ kMaxLevel
  int supersampling = 2;   // s: s×s directions per pixel, 1 ≤ s ≤ 64
  std::size_t keep = 64;   // coefficients kept per vertex (keepLargest), ≥ 1
  float offset = 1e-4f;    // origin shift along the normal, × the mesh's bounding radius; finite, ≥ 0
};

// Throws std::invalid_argument naming the bad option.
void checkVisibilityOptions(const VisibilityOptions& options);

// The visibility of every vertex of `mesh` against itself, in its object
// frame: keepLargest(forwardHaar(vertexVisibilityMap(…)), keep), one per
// vertex, in vertex order. Vertices are shared out over
// std::thread::hardware_concurrency() threads; progress(done, total), if
// given, is called on the calling thread as vertices complete (not
// necessarily for every count, always ending with done = total), and an
// exception from it stops the work and propagates. A mesh without normals
// gets area-weighted ones (Mesh::computeNormals) on a copy.
// Throws std::invalid_argument for bad options or an invalid mesh.
std::vector<SparseHaar> computeVertexVisibility(
    const Mesh& mesh, const VisibilityOptions& options,
    const std::function<void(std::size_t done, std::size_t total)>& progress = {});

// The same with the occluders given: `occluders` is any scene laid out in
// `mesh`'s object frame (usually RayScene({{&mesh}}); or the mesh plus a
// ground plane that moves with it). Lets a caller build the scene once for
// several calls.
std::vector<SparseHaar> computeVertexVisibility(
    const RayScene& occluders, const Mesh& mesh, const VisibilityOptions& options,
    const std::function<void(std::size_t done, std::size_t total)>& progress = {});

// `fused`'s visibility: every vertex's bits at options.level (one ray toward
// each pixel centre; supersampling and keep are not used), from the same ray
// start as the lists. Directions more than kBitsSkipBelowDegrees below the
// vertex's tangent plane are taken as occluded without a ray: the surface
// itself lies there unless it is thinner than the offset, and only a pixel
// whose interpolated normal leans that far from the vertex's could see them.
// Rays go 16 at a time as Embree packets sharing the vertex's origin, each
// a 4×4 block of neighbouring pixels; vertices are shared out over the
// threads as computeVertexVisibility does.
inline constexpr double kBitsSkipBelowDegrees = 15.0;
VisibilityBits computeVisibilityBits(const RayScene& occluders, const Mesh& mesh, const VisibilityOptions& options,
                                     const std::function<void(std::size_t done, std::size_t total)>& progress = {});
// The bits of vertices first… of `mesh` into `out` (pointCount() = the
// mesh's vertices, level = options.level), the others left as they are:
// what refining a mesh (visibility_refine.h) computes for the vertices it
// adds. progress counts those vertices.
void computeVisibilityBitsFrom(const RayScene& occluders, const Mesh& mesh, const VisibilityOptions& options,
                               std::size_t first, VisibilityBits& out,
                               const std::function<void(std::size_t done, std::size_t total)>& progress = {});
// The same against the mesh alone (normals made on a copy when it has none).
VisibilityBits computeVisibilityBits(const Mesh& mesh, const VisibilityOptions& options,
                                     const std::function<void(std::size_t done, std::size_t total)>& progress = {});

// The dense visibility map of one vertex (the map computeVertexVisibility
// truncates). `mesh` must have normals.
SphereMap vertexVisibilityMap(const RayScene& occluders, const Mesh& mesh, std::size_t vertex,
                              const VisibilityOptions& options);

// The dense visibility map seen from one point of the scene's frame, with no
// offset: pixel = the fraction (by solid angle) of its s×s stratified
// directions whose ray [tnear, ∞) escapes.
SphereMap pointVisibilityMap(const RayScene& occluders, const glm::vec3& origin, int level, int supersampling,
                             float tnear = 0.0f);

}  // namespace haarcast
