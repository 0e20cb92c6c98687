// The built-in environment: a procedural HDR sky with real dynamic range —
// a sky gradient, a ground, a small bright sun and a few bright windows —
// so that the default scene and the tests exercise all frequencies.
#pragma once

#include <array>

#include <glm/vec3.hpp>

#include "haarcast/core/sphere_map.h"

namespace haarcast::assets {

// Radiance (linear RGB) arriving from world direction `dir` (unit).
glm::dvec3 proceduralEnvironmentRadiance(const glm::dvec3& dir);

// The environment as a level-n map per channel, each pixel the average of
// its n×n stratified samples (so the small sun is not missed or aliased).
std::array<SphereMap, 3> proceduralEnvironment(int level, int supersampling = 8);

}  // namespace haarcast::assets
