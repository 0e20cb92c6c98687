// `fused`: the rotation and the triple product in one per-pixel sum
// (DESIGN.md "Per-pixel methods").
//
// A pixel needs I_c = Σ_ω L_c(ω)·V(ω)·ρ_c(Rᵀω)·ΔΩ(ω): the light (cut to its
// k largest Haar coefficients), the visibility (the barycentric blend of the
// hit triangle's three vertex lists) and the BRDF slice turned by the pixel's
// Y-X-Y rotation R. `spatial` forms ρ(Rᵀω) at every pixel centre by bilinear
// lookup and Haar-codes it, and the triple product then sums the three in the
// Haar basis. The Haar basis is orthonormal, so by Parseval that sum is the
// same number in the pixel basis — and there the rotated slice never has to be
// stored or transformed: each map direction ω looks up ρ at Rᵀω and is
// weighted by W_c(ω) = (L_c·ΔΩ)(ω)·V(ω) at once.
//
// What is shared, and when:
//   prepare   PixelSlices: the slices synthesised from their Haar
//             coefficients to pixel form (R, G, B texels), once per table;
//   per frame FusedLight: the truncated light L·ΔΩ of one object, synthesised
//             once per object;
//   per pixel the three vertex lists merged into one weighted coefficient
//             list and synthesised once; then one pass over the M² directions
//             computes the geometry of Rᵀω once for the three channels.
// The pass runs in float with SIMD through Google Highway (runtime dispatch:
// the best of SSE4/AVX2/AVX-512 or NEON the machine has).
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/fused_cells.h"
#include "haarcast/core/haar.h"
#include "haarcast/core/prefiltered_light.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/visibility_bits.h"

namespace haarcast {

// Throws std::invalid_argument naming the level unless it is one `fused` takes
// (shared::kMinLevel … shared::kFusedMaxLevel).
void checkFusedLevel(int level);

// The slice table in pixel form: texel (t, row, col) at
// ((t·M + row)·M + col)·4 = R, G, B, 0 (shared::kTexelFloats).
class PixelSlices {
 public:
  PixelSlices() = default;
  // Synthesises every slice of the table (inverse Haar per channel). The
  // point slices come from `pointTable` when given (the same BRDF and θₒ
  // at a level as fine or finer: render::pointLightLevel), else from `table`.
  // `detailMaps`: each slice's detail map too (detail()), for the sum by
  // cells (RenderOptions::sumTolerance > 0; level ≥ shared::kCellMinLevel).
  static PixelSlices synthesize(const BrdfSliceTable& table, const BrdfSliceTable* pointTable = nullptr,
                                bool detailMaps = false);

  int level() const { return level_; }
  // The point slices' level: level() or finer.
  int pointLevel() const { return pointLevel_; }
  int thetaSamples() const { return thetaSamples_; }
  std::span<const float> texels() const { return texels_; }
  const float* slice(int t) const;
  // Slice t as point values at the texel centres (shared::pointFromMean),
  // in the same layout at pointLevel(): what the point lights read
  // (shared::catmullRomWeights).
  const float* pointSlice(int t) const;
  std::span<const float> pointTexels() const { return pointTexels_; }
  // The last map row with a non-zero texel in any slice: below it every
  // lookup reads zeros (a slice is ρ·max(cos θᵢ, 0), so this is about the
  // equator), which lets the pass skip directions that cannot contribute.
  int lastNonZeroRow() const { return lastNonZeroRow_; }
  // Slice t's detail map at the cell level (fused_cells.h sliceDetail):
  // what the sum by cells reads; nullptr where synthesize made none (not
  // asked for, or below shared::kCellMinLevel).
  const float* detail(int t) const;
  std::size_t storedBytes() const { return (texels_.size() + pointTexels_.size() + detail_.size()) * sizeof(float); }
  // ∫ ρ_c dω of slice t (the directional albedo, cos θᵢ included), R, G, B.
  const std::array<float, 3>& energy(int t) const { return energy_.at(static_cast<std::size_t>(t)); }

 private:
  int level_ = 0;
  int pointLevel_ = 0;
  int thetaSamples_ = 0;
  int lastNonZeroRow_ = -1;
  std::vector<float> texels_;
  std::vector<float> pointTexels_;
  std::vector<float> detail_;  // slice t's at t·(M/4)²
  std::vector<std::array<float, 3>> energy_;
};

// One object's light for one frame in pixel form, three planes of M² floats
// (channel c at c·M²): the synthesis of L·ΔΩ as lightInObjectFrame cut it.
//
// With a sum tolerance τ > 0 at level ≥ shared::kCellMinLevel the light is
// also kept by cells (`cells`), and the pass sums by them (shared_cells.h):
// at one direction a cell where the slice's detail is at most τ.
struct FusedLight {
  int level = 0;
  std::vector<float> planes;
  float sumTolerance = 0.0f;
  CellLight cells;  // level 0: none, every direction is summed
  static FusedLight synthesize(const std::array<SparseHaar, 3>& light);
  // The light whole, from its pixel maps with ΔΩ already folded in
  // (SphereMap::weightedBySolidAngle): no Haar coding, no cut.
  static FusedLight fromWeightedMaps(const std::array<SphereMap, 3>& weighted, float sumTolerance = 0.0f);
  bool sumsByCells() const { return cells.level == level && level > 0; }
};

// A bright light taken out of the map (render/light_split.h) and shaded as a
// direction: I_c += power_c · ρ_c(Rᵀd) when the pixel sees it, ρ read from
// the point slices (PixelSlices::pointSlice) by Catmull-Rom. `direction`
// is a unit vector in the object's frame; power_c = Σ L_c·ΔΩ over the map
// texels it replaces.
struct FusedPointLight {
  glm::vec3 direction{0.0f, 1.0f, 0.0f};
  std::array<float, 3> power{};
};

// One of the hit triangle's vertices: its visibility list and barycentric weight.
struct WeightedVisibility {
  const SparseHaar* list = nullptr;
  float weight = 0.0f;
};

// Per-thread working memory: sized on first use, reused after (no allocation
// per pixel).
// Room for a sample's point lights (shared::kMaxPointLights) and a vector
// of the widest SIMD target past them, which the point lights' kernel reads
// whole (fused_kernel.h pointRho).
inline constexpr std::size_t kPointLightLanes = shared::kMaxPointLights + 16;

struct FusedScratch {
  std::vector<float> visibility;  // merged coefficients, then V in pixel form
  std::vector<float> synthesis;   // one inverse-Haar step
  std::vector<float> blended;     // the θₒ-blended slice, when the blend weight is not 0
  std::size_t blendedRows = 0;    // rows of `blended` that may be non-zero
  CellScratch cells;               // the adaptive pass's
  // The point lights a sample sees (at most shared::kMaxPointLights, padded
  // by a vector): directions, index, ρ by channel (fused_kernel.h pointRho).
  std::array<float, kPointLightLanes> lightX{}, lightY{}, lightZ{};
  std::array<std::uint32_t, shared::kMaxPointLights> lightIndex{};
  std::array<float, 3 * kPointLightLanes> lightRho{};
  // The last fusedShade's pass: the map directions it visited, its rows × M
  // (shared::passRows), or by cells one per coarse cell and 16 per fine
  // one; 0 where the lobe path took all.
  std::size_t passDirections = 0;
  CellCounts cellCounts;  // by cells: the last pass's coarse and fine cells
};

// One object's lobe path (shared_layout.h, "The lobe path"): its slices'
// lobes, the scene's prefiltered light and the turn from the object's frame
// into the light's (core/lobe.h chooseLobeCore decides which objects have
// one; `splitsum` reads its lobes and light whole).
struct LobePath {
  const PrefilteredLight* light = nullptr;
  std::span<const shared::SliceLobe> lobes;  // one per θₒ slice
  glm::mat3 toLight{1.0f};                   // object frame → the prefiltered light's frame
  // The lobes' core, measured with it (measureLobe): the path takes the
  // directions within it of the lobe's axis, the pass the rest. π: the
  // path takes all, and there is no pass.
  float coreAngle = static_cast<float>(kPi);
};

// The lobe path's radiance: E_c of the core·Σ_i w_i·L_c(R·ω_i), times the
// ray bit (shared::kLobeSeenBit) of the pixel's word.
std::array<float, 3> lobeShade(const LobePath& path, const shared::SliceBlend& blend, const EulerYXY& r,
                               std::uint32_t word);

// The pass's sum of a pixel, the part of fusedShade that is smooth across a
// surface (the light's rest × V × ρ, the energy put back, less the hidden
// sky): given, fusedShade takes it instead of summing (no slice blend, no
// pass, no hidden sky: `hidden` is not read), and everything else (point
// lights, lobe path) is the pixel's own; not given, fusedShade sums it and
// writes it here. core/shared_smooth.h takes it from a pixel's neighbours
// where they agree.
struct FusedSum {
  std::array<float, 3> value{};
  bool given = false;
};

// One pixel of `fused` with exact visibility: V(ω) = Σ_v b_v·bit_v(ω) blended
// from the hit triangle's vertices (visibility_bits.h), then the pass below;
// plus Σ_k power_k·ρ(Rᵀd_k) over the point lights whose bit k is set in
// `visibleLights` (each pixel's own shadow rays). With a lobe path, the pass
// leaves the directions within the path's core angle of the lobe's axis to
// lobeShade (and sums the lobe's energy less the core's), or is skipped
// when the path takes all. `hidden`, when given, is the sky other objects
// hide from the pixel (shared_rays.h HiddenLight): its power, the
// irradiance hidden, is taken off as a diffuse surface of the pass's
// albedo E_c would lose it, I_c −= power_c·E_c/π (from the pass's sum,
// before the point lights), the whole kept ≥ 0.
std::array<float, 3> fusedShade(const PixelSlices& slices, const shared::SliceBlend& blend, const EulerYXY& r,
                                const FusedLight& light, std::span<const WeightedBits> visibility,
                                std::span<const FusedPointLight> lights, std::uint32_t visibleLights,
                                FusedScratch& scratch, const LobePath* lobe = nullptr,
                                const std::array<float, 3>* hidden = nullptr, FusedSum* sum = nullptr);

// One pixel of `fused` from Haar visibility lists: Σ_ω W_c(ω)·ρ_c(Rᵀω) for c = R, G, B, with
// ρ = (1 − w)·slice[first] + w·slice[second] (shared::sliceBlendAt) looked up
// bilinearly exactly as rotateSpatialMap does (θ clamped at the poles, φ
// wrapped). Equal, to float rounding, to Σ_v weight_v·tripleProduct(light_c,
// rotateSpatial(slice), V_v). The lists and maps must share the slices' level
// (checked: std::invalid_argument).
std::array<float, 3> fusedShade(const PixelSlices& slices, const shared::SliceBlend& blend, const EulerYXY& r,
                                const FusedLight& light, std::span<const WeightedVisibility> visibility,
                                FusedScratch& scratch);

// The SIMD target the pass dispatches to on this machine ("AVX3", "AVX2", …).
std::string fusedTargetName();

// The bytes one pixel reads in the pass: one slice (two when blending), the
// light planes and its visibility (bits or lists, in the caller's format).
std::size_t fusedPixelBytes(int level, bool blended, std::size_t visibilityBytes);

}  // namespace haarcast
