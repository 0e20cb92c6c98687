// Ray casting against one or more meshes, each placed by an object-to-world
// transform: an RAII wrapper of an Embree 3 scene. Every RayScene of the
// process shares one Embree device, made by the first (as the Vulkan
// backend shares its instance and device, gpu/engine.h). Used for the
// per-vertex visibility of one object (in its own frame: identity transform)
// and, later, by the CPU reference renderer and the Monte Carlo reference for
// scenes of several objects.
//
// Every Embree call made while building or updating is checked: a failure
// throws std::runtime_error naming the call, Embree's error code and its
// message. Queries (intersect, occluded, occludedBatch) on a built scene are
// const and safe to call from many threads at once; they are not checked per
// ray (a committed scene cannot fail a well-formed query, and the check would
// cost as much as a short ray).
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "haarcast/core/mesh.h"

namespace haarcast {

// One placed mesh. The mesh is copied into Embree's buffers while the
// RayScene is built, so it need only outlive the constructor. Instances that
// point at the same Mesh share one acceleration structure (Embree instancing).
struct Instance {
  const Mesh* mesh = nullptr;
  // Column-major (glm) object-to-world transform. It must be affine (last row
  // 0 0 0 1), finite and invertible; a 3×4 transform is this with that row.
  glm::mat4 objectToWorld{1.0f};
};

// A ray o + t·d, t ∈ [tnear, tfar]. d need not be unit length; t is in
// units of |d|. Both ends must be ≥ 0 (Embree's contract).
struct Ray {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f, 1.0f, 0.0f};
  float tnear = 0.0f;
  float tfar = std::numeric_limits<float>::infinity();
};

// The closest hit of a ray. The point is o + t·d, or equally, on triangle
// (p0, p1, p2) of the object's mesh, (1 − u − v)·p0 + u·p1 + v·p2.
struct Hit {
  std::uint32_t object = 0;    // index into the instances the scene was built from
  std::uint32_t triangle = 0;  // index into that mesh's triangles
  float u = 0.0f, v = 0.0f;    // barycentrics of p1 and p2
  float t = 0.0f;
  // Unit geometric normal in the world frame, (p1 − p0) × (p2 − p0) carried
  // through the instance's transform: it faces where the winding says, not
  // necessarily toward the ray.
  glm::vec3 geometricNormal{0.0f, 1.0f, 0.0f};
};

class RayScene {
 public:
  // Validates every mesh (Mesh::validate) and every transform first — bad
  // input is std::invalid_argument, before Embree sees it — then builds.
  // At least one instance is required.
  explicit RayScene(std::vector<Instance> instances);
  ~RayScene();
  RayScene(RayScene&&) noexcept;
  RayScene& operator=(RayScene&&) noexcept;
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  std::size_t objectCount() const;
  // Embree devices this process has made (rtcNewDevice): 1 once any scene
  // exists, however many; what a test checks.
  static std::uint64_t devicesCreated();

  // Closest hit in [tnear, tfar], or none. Thread-safe.
  std::optional<Hit> intersect(const Ray& ray) const;
  // intersect() for rays that share an origin (a pinhole camera's), as
  // Embree packets of 16 consecutive directions with the coherent hint:
  // out[i] = the closest hit of origin + t·directions[i], t ∈ [tnear, ∞).
  // Fastest when each 16 are neighbours (a 4×4 block of pixels).
  // Thread-safe. Throws std::invalid_argument if the spans differ in size.
  void intersectFrom(const glm::vec3& origin, float tnear, std::span<const glm::vec3> directions,
                     std::span<std::optional<Hit>> out) const;
  // Whether anything lies in [tnear, tfar] (any hit, not the closest: cheaper).
  // Thread-safe.
  bool occluded(const Ray& ray) const;
  // occluded() for many rays in one call (Embree ray streams): out[i] = 1 if
  // rays[i] is blocked, else 0. `coherent` tells Embree the rays are alike
  // (e.g. one origin, neighbouring directions), which lets it trace them as
  // packets. Thread-safe. Throws std::invalid_argument if the spans differ in size.
  void occludedBatch(std::span<const Ray> rays, std::span<std::uint8_t> out, bool coherent = false) const;

  // occluded() for rays that share an origin (one point's directions), as
  // Embree packets of 16 consecutive directions (without the coherent hint:
  // embree_scene.cpp says why): out[i] = 1 if the ray origin + t·directions[i], t ∈ [tnear, ∞), is
  // blocked. Fastest when each 16 are neighbours (a 4×4 block of map
  // pixels). Thread-safe. Throws std::invalid_argument if the spans differ
  // in size.
  void occludedFrom(const glm::vec3& origin, float tnear, std::span<const glm::vec3> directions,
                    std::span<std::uint8_t> out) const;
  // occluded() for rays that share a direction (many points toward one
  // light), as Embree packets of 16 consecutive origins: out[i] = 1 if origins[i] + t·direction, t ∈ [tnear, ∞), is
  // blocked. Fastest when each 16 are neighbours (a pixel row's points).
  // Thread-safe. Throws std::invalid_argument if the spans differ in size.
  void occludedToward(std::span<const glm::vec3> origins, const glm::vec3& direction, float tnear,
                      std::span<std::uint8_t> out) const;
  // occludedFrom() against object `object` alone, as posed (what it blocks
  // of the rays, whatever else lies in front or behind): the test of what
  // an object hides from itself. Thread-safe.
  void occludedByObjectFrom(std::size_t object, const glm::vec3& origin, float tnear, std::span<const glm::vec3> directions,
                            std::span<std::uint8_t> out) const;
  // Moves object `object` and rebuilds the top level only (the meshes'
  // structures are kept): the per-frame path for posed objects. Not safe
  // while another thread queries this scene.
  void setTransform(std::size_t object, const glm::mat4& objectToWorld);

 private:
  // A hit as Embree reports it: the normal Ng in the object's frame, unnormalised.
  Hit hitOf(unsigned object, unsigned triangle, float u, float v, float t, const glm::vec3& ng) const;

  struct Impl;
  std::unique_ptr<Impl> impl_;  // null only after a move
};

}  // namespace haarcast
