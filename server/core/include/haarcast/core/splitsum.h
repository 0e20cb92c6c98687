// `splitsum`: the image-based lighting of real-time engines (Karis 2013,
// "Real Shading in Unreal Engine 4"; Lagarde & de Rousiers 2014, "Moving
// Frostbite to PBR"), kept as a baseline for speed and truth beside the
// methods that rotate slices (DESIGN.md "Per-pixel methods").
//
// Engines split ∫L·ρ·cos θᵢ dω into two lookups: the BRDF's directional
// albedo, tabulated by roughness and θₒ, times the light prefiltered by the
// lobe, read along the reflection direction at the mip of the roughness.
// Here both come from this project's own measurements:
//   precompute  the lobe per θₒ sample (core/lobe.h measureLobe: E_c =
//               ∫ρ_c·cos θᵢ dω and the lobe's median angle), 64 bytes each
//               and nothing else: no slice tables, no rotations, no
//               per-vertex visibility;
//   per scene   the light prefiltered to every level (core/prefiltered_light.h),
//               shared with `fused`'s lobe path;
//   per pixel   I_c = E_c(θₒ)·L_c(λ, R·m)·V: the lobes of θₒ blended as the
//               slices are (shared::sliceBlendAt), m = (0, cos θₒ, −sin θₒ)
//               the mirror direction in the slice's frame turned by the
//               pixel's rotation into the light's frame, λ =
//               shared::splitsumLevel(the lobe's median angle) (trilinear),
//               and V one shadow ray along m (shared::kLobeSeenBit).
//
// What it gives up, by design (the truth it loses is measured by `eval
// --methods-only`): the lobe is one isotropic filter about the mirror
// direction, so a lobe's shape (GGX stretched at grazing angles, the
// off-specular peak of a rough lobe) and the light's variation inside it are
// lost; visibility is one ray, all or nothing for the whole lobe. A diffuse
// or wide lobe is read the same way: about the mirror direction at a coarse
// level (a Lambert lobe's median angle is ~1 rad, λ ≈ 1), not as irradiance
// about the normal as engines' separate diffuse term would (a measured BRDF
// has no diffuse/specular split to take), which is fair at normal
// incidence and biased toward the horizon at grazing angles; its shadow is
// the mirror ray's, so a rough object's self-shadowing and a Lambert
// ground's shadows are those of a mirror.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "haarcast/core/fused.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/shared_layout.h"

namespace haarcast {

// θₒ of lobe sample t of T: (t + ½)·(π/2)/T, the slice tables' layout
// (BrdfSliceTable::thetaOut), so that shared::sliceBlendAt blends lobes
// as it blends slices. Throws std::invalid_argument unless T ≥ 1.
std::vector<double> lobeThetaOut(int thetaSamples);

// One pixel of `splitsum`: E_c·L_c(λ, R·m)·V (above), with `path`'s lobes
// (one per θₒ sample), prefiltered light and turn into the light's frame;
// V = 1 when the word has shared::kLobeSeenBit, else the pixel is black.
std::array<float, 3> splitsumShade(const LobePath& path, const shared::SliceBlend& blend, const EulerYXY& r,
                                   double thetaOut, std::uint32_t word);

// The mirror direction of θₒ in the light's frame: toLight·R·(0, cos θₒ, −sin θₒ).
glm::vec3 splitsumMirror(const glm::mat3& toLight, const EulerYXY& r, double thetaOut);

// What `splitsum` keeps per material: T lobes (shared::SliceLobe).
std::size_t splitsumStoredBytes(int thetaSamples);
// What one pixel reads: two lobes and the 8 texels of a trilinear lookup.
std::size_t splitsumPixelBytes();

}  // namespace haarcast
