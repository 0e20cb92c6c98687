// The light split in two (DESIGN.md "Per-pixel methods", docs/design.md
// "Visibility"): its few brightest, most compact regions (small suns, bright
// windows) taken out of the map as directional lights, and the rest.
//
// Why: per-vertex visibility, however exact at its vertices, is blended
// across each triangle, so a sharp shadow edge from a small bright light
// cannot fall inside one. Those lights carry most of the energy of a sunny
// sky, so `fused` gives each pixel its own shadow ray toward each of them
// (against every object of the scene, the ground included: shadows between
// objects come from the same rays) and keeps the map, with vertex
// visibility, for the rest. Nothing is lost or counted twice: the rest is
// the map with the lights' texels set to zero, and each light carries
// exactly the power Σ L·ΔΩ of the texels it took.
//
// How (once per environment, in its own frame):
//   1. seeds: texels whose luminance is at least `seedRatio` × the map's
//      mean radiance (∫L dω / 4π), brightest first;
//   2. each unclaimed seed grows a region over its 8 neighbours (φ wraps)
//      while a neighbour is at least `growRatio` × the seed's luminance and
//      within `maxRadiusDegrees` of the seed's direction;
//   3. a region becomes a light when its power is at least `minShare` of the
//      map's total power; at most `maxLights`, brightest seed first. Its
//      direction is the power-weighted mean of its texel centres.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include <glm/vec3.hpp>

#include "haarcast/core/sphere_map.h"

namespace haarcast {

struct LightSplitOptions {
  std::size_t maxLights = 16;       // ≤ 32: one bit per light per pixel
  double seedRatio = 16.0;          // × mean radiance
  double growRatio = 0.05;          // × the seed's luminance
  double maxRadiusDegrees = 6.0;    // a region's extent from its seed
  double minShare = 0.005;          // of the total power
  // Each region becomes this many lights, 1 or 4: its texels parted in four
  // quadrants about its centre (a penumbra in five steps instead of a hard
  // edge). Regions are taken while their lights fit in maxLights.
  std::size_t parts = 4;
};

struct DirectionalLight {
  glm::dvec3 direction{0.0, 1.0, 0.0};  // unit, toward the light, in the map's frame
  std::array<double, 3> power{};        // Σ L_c·ΔΩ over its texels
  std::size_t texels = 0;
};

struct LightSplit {
  std::vector<DirectionalLight> lights;
  std::array<SphereMap, 3> rest;        // radiance, the lights' texels zeroed
};

// Throws std::invalid_argument for options out of range or maps of unequal levels.
LightSplit splitLight(const std::array<SphereMap, 3>& light, const LightSplitOptions& options = {});

// The lights found on `fine`, a finer map of the same environment, and the
// rest at `level` (≤ fine's level): the solid-angle mean of fine's rest
// (SphereMap::downsampled), so power is still neither lost nor counted
// twice. Why: a light's direction is the mean of its texel centres, and a
// sun smaller than a texel would sit at its texel's centre, up to half a
// texel off (2.8° at level 6: a shadow 5 cm off behind a 1 m pillar). On
// the backdrop's level-9 map it is within a tenth of a degree.
LightSplit splitLight(const std::array<SphereMap, 3>& fine, int level, const LightSplitOptions& options = {});

// Luminance of linear Rec. 709 RGB (the weights render/tonemap.h uses).
inline double luminance709(double r, double g, double b) { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }

}  // namespace haarcast
