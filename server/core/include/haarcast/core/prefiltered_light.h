// The light prefiltered for lobes (shared_layout.h, "The lobe path"): the
// environment's maps averaged to every level from its finest down to one
// texel — its Haar scaling coefficients, in pixel form — so that a lobe is
// read as Σ_l w_l·L_l(axis) with w_l the share of its energy at level l's
// width. Built once per scene in the environment's frame; a frame turns
// the lookup direction instead of the maps.
#pragma once

#include <array>
#include <span>
#include <vector>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "haarcast/core/shared_layout.h"
#include "haarcast/core/sphere_map.h"

namespace haarcast {

class PrefilteredLight {
 public:
  PrefilteredLight() = default;
  // From radiance maps of one level ≤ shared::kLobeLevels − 1 (R, G, B):
  // level l is the solid-angle mean over each of its texels
  // (SphereMap::downsampled), so every level keeps the light's integral.
  static PrefilteredLight build(const std::array<SphereMap, 3>& maps);

  bool empty() const { return texels_.empty(); }
  int finestLevel() const { return finest_; }
  // Level l's texels at shared::prefilterOffset(l), row-major, RGB0.
  std::span<const glm::vec4> texels() const { return texels_; }

  // Level l bilinear at a unit direction of the environment's frame
  // (shared::latLongTaps).
  glm::vec3 sampleLevel(int level, const glm::vec3& direction) const;
  // Level λ ∈ [0, finest] (clamped), trilinear: the bilinear lookups of
  // ⌊λ⌋ and ⌊λ⌋ + 1 blended by λ's fraction.
  glm::vec3 sample(float level, const glm::vec3& direction) const;
  // The lobe's light per unit of its energy: the mean over its K·J
  // stratified directions (shared_layout.h, "The lobe path") about `axis`,
  // with u, v completing an orthonormal frame, all in the light's frame.
  glm::vec3 lobe(const shared::SliceLobe& lobe, const glm::vec3& axis, const glm::vec3& u, const glm::vec3& v) const;

 private:
  int finest_ = -1;
  std::vector<glm::vec4> texels_;
};

}  // namespace haarcast
