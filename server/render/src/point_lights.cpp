// Shadow rays toward the point lights (point_lights.h).
#include "haarcast/render/point_lights.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>

#include "haarcast/core/check.h"
#include "haarcast/core/shared_layout.h"

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

float groundSkyOcclusion(const RayScene& world, const ShadingPoint& p, const GroundSky& sky) {
  if (!(sky.total > 0.0) || sky.occluders.empty()) return 0.0f;
  const glm::vec3 origin = p.position + p.normal * p.shift;
  constexpr int kSamples = kGroundSkyRings * kGroundSkySectors;
  std::vector<glm::vec3> directions;
  std::vector<float> weights;  // luminance·cos·ΔΩ of each direction
  for (std::size_t k = 0; k < sky.occluders.size(); ++k) {
    const glm::vec3 centre(sky.occluders[k]);
    const float radius = sky.occluders[k].w;
    const glm::vec3 toward = centre - origin;
    const float distance = glm::length(toward);
    if (!(distance > 0.0f)) continue;
    const glm::vec3 axis = toward / distance;
    // The cone's half-angle; inside the sphere, the hemisphere about the axis.
    const float cosAlpha = distance > radius ? std::sqrt(1.0f - (radius / distance) * (radius / distance)) : 0.0f;
    const float sinAlpha = std::sqrt(std::max(0.0f, 1.0f - cosAlpha * cosAlpha));
    const float solid = static_cast<float>(kTwoPi) * (1.0f - cosAlpha);
    // Its largest cosine with the ground's normal bounds what it can hide.
    const float cosAxis = glm::dot(axis, p.normal);
    const float sinAxis = std::sqrt(std::max(0.0f, 1.0f - cosAxis * cosAxis));
    const float cosMax = cosAxis >= cosAlpha ? 1.0f : cosAxis * cosAlpha + sinAxis * sinAlpha;
    if (cosMax <= 0.0f || solid * cosMax / static_cast<float>(kPi) < sky.minShare) continue;
    const glm::vec3 helper = std::abs(axis.y) < 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
    const glm::vec3 t1 = glm::normalize(glm::cross(helper, axis));
    const glm::vec3 t2 = glm::cross(axis, t1);
    for (int ring = 0; ring < kGroundSkyRings; ++ring) {
      // Equal solid angle per ring: cos θ uniform over [cos α, 1].
      const float cosTheta = 1.0f - (static_cast<float>(ring) + 0.5f) / kGroundSkyRings * (1.0f - cosAlpha);
      const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
      for (int sector = 0; sector < kGroundSkySectors; ++sector) {
        const float phi = static_cast<float>(kTwoPi) * (static_cast<float>(sector) + 0.5f * static_cast<float>(ring % 2) + 0.25f) /
                          kGroundSkySectors;
        const glm::vec3 d = sinTheta * std::cos(phi) * t1 + sinTheta * std::sin(phi) * t2 + cosTheta * axis;
        const float cosine = glm::dot(d, p.normal);
        if (cosine <= 0.0f) continue;
        // Counted once: a direction inside an earlier object's cone was taken there.
        bool earlier = false;
        for (std::size_t j = 0; j < k && !earlier; ++j) {
          const glm::vec3 c(sky.occluders[j]);
          const float dj = glm::length(c - origin);
          const float cj = dj > sky.occluders[j].w ? std::sqrt(1.0f - (sky.occluders[j].w / dj) * (sky.occluders[j].w / dj)) : 0.0f;
          earlier = dj > 0.0f && glm::dot(d, (c - origin) / dj) > cj;
        }
        if (earlier) continue;
        const Spherical s = directionToSpherical(glm::dvec3(sky.toEnvironment * d));
        directions.push_back(d);
        weights.push_back(static_cast<float>(sky.luminance.sampleBilinear(s.theta, s.phi)) * cosine * solid / kSamples);
      }
    }
  }
  if (directions.empty()) return 0.0f;
  std::vector<std::uint8_t> blocked(directions.size());
  world.occludedFrom(origin, 0.0f, directions, blocked);
  double hidden = 0.0;
  for (std::size_t i = 0; i < directions.size(); ++i) hidden += blocked[i] ? weights[i] : 0.0f;
  return static_cast<float>(std::clamp(hidden / sky.total, 0.0, 1.0));
}

std::uint32_t withGroundOcclusion(std::uint32_t lightBits, float occlusion) {
  HC_CHECK_LT(lightBits, 1u << shared::kGroundOcclusionShift);
  const float share = std::clamp(occlusion, 0.0f, 1.0f);
  return lightBits | (static_cast<std::uint32_t>(std::lround(share * shared::kGroundOcclusionSteps)) << shared::kGroundOcclusionShift);
}

}  // namespace haarcast::render
