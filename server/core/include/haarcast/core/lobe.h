// A BRDF slice's lobe, measured from the BRDF itself rather than from its
// level-n slice map, whose texels blur a mirror's lobe to their own size:
// its energy, its axis, and how its energy spreads with the angle from the
// axis (shared::SliceLobe). `fused` sends the lobes its maps cannot
// resolve down the lobe path (fused.h), and `splitsum` sends every lobe.
#pragma once

#include <vector>

#include "haarcast/core/brdf.h"
#include "haarcast/core/shared_layout.h"

namespace haarcast {

// The lobe of ρ(·, ωₒ)·cos θᵢ with ωₒ = (0, cos θₒ, sin θₒ) (the slice's
// frame, BrdfSliceTable). Measured on a polar grid about the mirror
// direction (rings log-spaced in angle from 10⁻⁴ rad to π, so a lobe of a
// hundredth of a degree is still resolved): its energy, and the angles
// that split it into shared::kLobeRings equal shares.
shared::SliceLobe measureLobe(const Brdf& brdf, double thetaOut);

// measureLobe at each θₒ, on parallelFor's threads.
std::vector<shared::SliceLobe> measureLobes(const Brdf& brdf, const std::vector<double>& thetaOut);

}  // namespace haarcast
