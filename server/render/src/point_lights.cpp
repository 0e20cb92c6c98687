// Shadow rays toward the point lights (point_lights.h).
#include "haarcast/render/point_lights.h"

#include <cmath>

#include <glm/geometric.hpp>

#include "haarcast/core/check.h"

namespace haarcast::render {

ShadingPoint shadingPoint(const Mesh& mesh, const glm::uvec3& triangle, const float b[3], const glm::mat4& objectToWorld,
                          const glm::mat3& rotation, float shift) {
  const glm::vec3 p = b[0] * mesh.positions[triangle.x] + b[1] * mesh.positions[triangle.y] + b[2] * mesh.positions[triangle.z];
  const glm::vec3 n = b[0] * mesh.normals[triangle.x] + b[1] * mesh.normals[triangle.y] + b[2] * mesh.normals[triangle.z];
  ShadingPoint s;
  s.position = glm::vec3(objectToWorld * glm::vec4(p, 1.0f));
  // A pose scales uniformly, so normals turn with its rotation alone.
  const glm::vec3 world = rotation * n;
  const float len = glm::length(world);
  s.normal = len > 0.0f && std::isfinite(len) ? world / len : glm::vec3(0.0f);
  s.shift = shift;
  return s;
}

std::uint32_t pointLightMask(const RayScene& world, const ShadingPoint& p, std::span<const glm::vec3> directions) {
  HC_CHECK_LE(directions.size(), std::size_t{32});
  std::uint32_t mask = 0;
  for (std::size_t k = 0; k < directions.size(); ++k) {
    if (!(glm::dot(p.normal, directions[k]) > 0.0f)) continue;  // below the shading horizon: ρ·cos is 0
    Ray r;
    r.origin = p.position + p.normal * p.shift;
    r.direction = directions[k];
    if (!world.occluded(r)) mask |= 1u << k;
  }
  return mask;
}

}  // namespace haarcast::render
