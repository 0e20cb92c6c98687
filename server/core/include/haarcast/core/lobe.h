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
// hundredth of a degree is still resolved): its energy, and the angles
// that split it into shared::kLobeRings equal shares.
//
// coreAngle: the lobe path's part of it. Its samples and `core` cover the
// angles up to coreAngle from the axis; the rest is left to the pass over
// the maps (fused.h). π: all of it.
shared::SliceLobe measureLobe(const Brdf& brdf, double thetaOut, double coreAngle = kPi);

// measureLobe at each θₒ, on parallelFor's threads.
std::vector<shared::SliceLobe> measureLobes(const Brdf& brdf, const std::vector<double>& thetaOut, double coreAngle = kPi);

// How `fused` divides an object's lobes between the pass over the level-n
// maps and the lobe path (fused.h LobePath), from their measurement at the
// core angle kLobeCoreTexels·π/2ⁿ:
// - the path takes all of every lobe (coreAngle π, lobes remeasured so) when
//   at every θₒ less than kLobeTailLeft of the energy lies outside the core:
//   the pass would add little at the cost of a whole pass;
// - none (coreAngle 0, no lobes) when at every θₒ less than kLobeCoreMin
//   lies inside it: the maps resolve such a lobe (a rough metal's);
// - else the core, and the pass the rest (a mirror with a haze, such as
//   measured chrome, whose wide part the pass resolves and the path could
//   only blur about the mirror direction).
inline constexpr double kLobeCoreTexels = 2.0;
inline constexpr double kLobeTailLeft = 0.02;
inline constexpr double kLobeCoreMin = 0.25;
struct LobeCore {
  float angle = 0.0f;                     // 0: no lobe path; π: the path takes all
  std::vector<shared::SliceLobe> lobes;  // measured with `angle` (empty for 0)
};
LobeCore chooseLobeCore(const Brdf& brdf, const std::vector<double>& thetaOut, int level);

}  // namespace haarcast
