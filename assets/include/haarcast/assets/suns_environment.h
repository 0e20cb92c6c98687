// The built-in environment for shadow tests, "suns": a dim, smooth sky and
// three small bright suns at different elevations. The suns carry most of
// the light (about 80 % of the irradiance on an upward-facing surface), so
// what a surface sees of them decides its brightness: sharp cast shadows,
// each sun's own, the case a band-limited light and per-vertex visibility
// find hardest.
//
// The sky (world frame, +Y up) is piecewise linear in y = cos θ: kHorizon at
// y = 0, kZenith at y = 1, kNadir at y = −1; continuous, no hard horizon.
// A sun of angular radius ρ has its full radiance out to ρ/2 and a
// smoothstep limb from ρ/2 to 0 at ρ, so it is well defined at every map
// level (procedural_environment.h says why a soft edge).
//
// The maps are exact area averages, not point samples: the sky's by its
// integral over each row in y (it is linear in y there), each sun's by a
// fine midpoint quadrature over its bounding box in (cos θ, φ), each cell
// credited to the pixel holding its centre. The maps' integral equals the
// radiance function's to float rounding, at every level.
#pragma once

#include <array>
#include <span>

#include <glm/vec3.hpp>

#include "haarcast/core/sphere_map.h"

namespace haarcast::assets {

struct Sun {
  double elevationDeg;  // above the horizon
  double azimuthDeg;    // φ, from +Z toward +X
  double radiusDeg;     // angular radius ρ: full radiance to ρ/2, none beyond ρ
  glm::dvec3 radiance;  // linear RGB at the core
};

struct SunsSky {
  glm::dvec3 zenith, horizon, nadir;  // the sky's radiance at y = 1, 0, −1
  std::span<const Sun> suns;
};

// The parameters, as the radiance function and the maps use them.
const SunsSky& sunsSky();

// A sun's weight at `angle` from its centre: 1 inside ρ/2, smoothstep to 0 at ρ.
double sunLimb(double angle, double radius);

// Radiance (linear RGB) arriving from world direction `dir` (unit).
glm::dvec3 sunsEnvironmentRadiance(const glm::dvec3& dir);

// The level-n maps (one per channel) of pixel area averages. level ∈ [0, kMaxLevel].
std::array<SphereMap, 3> sunsEnvironment(int level);

}  // namespace haarcast::assets
