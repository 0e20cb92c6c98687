// A BRDF slice's lobe, measured from the BRDF itself rather than from its
// level-n slice map, whose texels blur a mirror's lobe to their own size:
// its energy, its axis, and how its energy spreads with the angle from the
// axis (shared::SliceLobe). `fused` sends the lobes its maps cannot
// resolve down the lobe path (fused.h), and `splitsum` sends every lobe.
#pragma once

#include <span>
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
// The same from lobes already measured at those θₒ (measureLobes with the
// whole lobe, coreAngle π), which it keeps when no core is needed.
LobeCore chooseLobeCore(const Brdf& brdf, const std::vector<double>& thetaOut, int level,
                        std::vector<shared::SliceLobe> lobes);

// The map level `fused` gives an object when the levels are chosen per
// object (render::RenderOptions::automaticLevel), in two steps:
// 1. the smallest n in [floor, cap] at which the sharpest slice's median
//    angle m spans at least kLevelMedianTexels texels, m ≥ K·π/2ⁿ, i.e.
//    n = ⌈log₂(K·π/m)⌉: the texels then resolve the lobe's bulk, and each
//    finer level costs 4× per pixel for little (below). A lobe too narrow
//    even at the cap gets the cap;
// 2. where the lobe path takes every slice's whole lobe at some level in
//    [floor, n) (chooseLobeCore's angle π: a near-mirror), the coarsest
//    such level instead. That path reads the prefiltered light along the
//    lobe and one ray, never the maps or the visibility bits, so the
//    object's pixels are the same at every such level; at a finer one its
//    core shrinks with the texels and a pass over the maps takes the tail
//    (ggx:0.02: 4.4 % relative L2 whole at level 5, 4.4 % split at 6,
//    7.4 % at 7, docs/evaluation.md "Sharp materials").
//
// K and the floor were tuned on the relative L2 of `fused` against the
// converged Monte Carlo reference at levels 3–7, under
// adams_place_bridge_1k.hdr (docs/evaluation.md, "A level per object"):
// spheres of Lambert, ggx:0.3, ggx:0.1, blue-metallic-paint and
// alum-bronze (96²), and a tilted torus, which shades itself, of Lambert
// and ggx:0.3 (128²). With the median over 8 or more texels every case was
// within 1.6× of its level-7 error (the spheres within 1.02×); at 4–5
// texels the spheres were within 1.3× but the torus 4.1× (ggx:0.3) and
// 4.9× (Lambert) off it, at 2–3 texels 1.3–12×. Lambert, the widest lobe
// (m = 45°), gets the floor by the rule: at level 4 its torus was 4.9× off.
inline constexpr double kLevelMedianTexels = 8.0;
inline constexpr int kAutoLevelFloor = 5;
// The sharpest (smallest) median angle of the lobes; π when there are none.
double sharpestMedian(std::span<const shared::SliceLobe> lobes);
// Step 1 of the rule, for an object's lobes (measureLobes at its table's
// θₒ, the whole lobe). A cap below the floor is the level.
int chooseLevel(std::span<const shared::SliceLobe> lobes, int cap, int floor = kAutoLevelFloor);
// Both steps: the level `fused` gives an object of this BRDF.
int chooseLevel(const Brdf& brdf, const std::vector<double>& thetaOut, std::span<const shared::SliceLobe> lobes,
                int cap, int floor = kAutoLevelFloor);

}  // namespace haarcast
