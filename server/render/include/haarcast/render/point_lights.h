// The per-pixel half of `fused`'s light split (core/light_split.h): which of
// the point lights a shading point sees, by one shadow ray each against the
// whole posed scene — every object and the ground — so shadows between
// objects, on the ground and from a light's exact direction come from the
// same rays, and move with the objects in the frame they move.
//
// Both backends call pointLightMask with the same inputs (the hit triangle,
// its barycentrics as float, the object's pose), so the CPU and the Vulkan
// backend (which reads its rasterised G-buffer's samples back for it) give
// the same bits.
#pragma once

#include <cstdint>
#include <span>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "haarcast/core/mesh.h"
#include "haarcast/render/embree_scene.h"

namespace haarcast::render {

// Where a sample's shadow rays start, in the world frame: the point on the
// hit triangle, and the unit shading normal (the barycentric blend of the
// vertex normals), and the origin's shift along it.
struct ShadingPoint {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 1.0f, 0.0f};
  float shift = 0.0f;
};

// The shift is VisibilityOptions::offset × the mesh's bounding radius × the
// pose's scale: the rule of the per-vertex visibility and of the Monte Carlo
// reference (reference.h), in world units.
// `rotation` is the pose's (object → world; poses scale uniformly).
ShadingPoint shadingPoint(const Mesh& mesh, const glm::uvec3& triangle, const float b[3], const glm::mat4& objectToWorld,
                          const glm::mat3& rotation, float shift);

// Bit k set when the point sees direction k (world frame, unit): n·d_k > 0
// and the ray from position + shift·n toward d_k escapes. At most 32 directions.
std::uint32_t pointLightMask(const RayScene& world, const ShadingPoint& p, std::span<const glm::vec3> directions);

}  // namespace haarcast::render
