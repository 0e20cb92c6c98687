// A BRDF slice's lobe, measured from the BRDF itself rather than from its
// level-n slice map, whose texels blur a mirror's lobe to their own size:
// its energy, its axis, and how its energy spreads with the angle from the
// axis (shared::SliceLobe). `fused` sends the lobes its maps cannot
// resolve down the lobe path (fused.h), and `splitsum` sends every lobe.
#pragma once

#include <vector>

#include "haarcast/core/brdf.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/sphere_map.h"

namespace haarcast {

// The lobe of ρ(·, ωₒ)·cos θᵢ with ωₒ = (0, cos θₒ, sin θₒ) (the slice's
// frame, BrdfSliceTable). Measured on a polar grid about the mirror
// direction (rings log-spaced in angle from 10⁻⁴ rad to π, so a lobe of a
// hundredth of a degree is still resolved): its energy, its median angle,
// and the lobe path's samples (shared_layout.h, "The lobe path").
//
// coreAngle: the lobe path's part of it. Its samples and `core` cover the
// angles up to coreAngle from the axis; the rest is left to the pass over
// the maps (fused.h). π: all of it.
shared::SliceLobe measureLobe(const Brdf& brdf, double thetaOut, double coreAngle = kPi);

// measureLobe at each θₒ, on parallelFor's threads.
std::vector<shared::SliceLobe> measureLobes(const Brdf& brdf, const std::vector<double>& thetaOut, double coreAngle = kPi);

// How `fused` divides an object's lobes between the pass over the level-n
// maps and the lobe path (fused.h LobePath), texel = π/2ⁿ:
// - none (angle 0, no lobes) when even its sharpest slice's median angle is
//   more than kLobeMedianTexels texels: the maps resolve it (a glossy
//   metal's, a Phong lobe's), and the pass sees its visibility direction by
//   direction, where the path has one ray;
// - else the path takes all of every lobe (angle π) when at every θₒ less
//   than kLobeTailLeft of the energy lies beyond kLobeCoreTexels texels of
//   the axis: a pass would add little at the cost of a whole pass;
// - else it takes that core and the pass the rest: a mirror with a haze,
//   as measured chrome, whose wide part the pass resolves and the path
//   could only blur about the mirror direction. A core of 4 texels keeps
//   the lobe's flanks, which the slice texels' point samples step over,
//   out of the pass (at 2 texels a GGX 0.02 sphere at level 7 measured
//   16 % relative L2 against the truth, at 4 texels 7.4 %).
inline constexpr double kLobeMedianTexels = 1.0;
inline constexpr double kLobeCoreTexels = 4.0;
inline constexpr double kLobeTailLeft = 0.02;
struct LobeCore {
  float angle = 0.0f;                     // 0: no lobe path; π: the path takes all
  std::vector<shared::SliceLobe> lobes;  // measured with `angle` (empty for 0)
};
LobeCore chooseLobeCore(const Brdf& brdf, const std::vector<double>& thetaOut, int level);

}  // namespace haarcast
