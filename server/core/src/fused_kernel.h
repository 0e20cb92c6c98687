// The SIMD pass of `fused` (fused_kernel.cpp, one copy per Highway target,
// dispatched at run time). fused.cpp prepares its inputs.
#pragma once

#include <cstddef>
#include <cstdint>

namespace haarcast {
struct CellDirections;
struct CellLight;
struct CellScratch;
struct CellCounts;
}  // namespace haarcast

namespace haarcast::detail {

// Unit directions of the pixel centres of a level's map, planar (N each).
struct PixelDirections {
  const float* x = nullptr;
  const float* y = nullptr;
  const float* z = nullptr;
  const float* solidAngle = nullptr;  // ΔΩ of each pixel
};
const PixelDirections& pixelDirections(int level);

struct FusedPass {
  int level = 0;
  const float* slice = nullptr;   // R, G, B, 0 texels (shared::kTexelFloats)
  const float* light = nullptr;       // L_c·ΔΩ, three planes of N
  const float* visibility = nullptr;  // V, N; or, when null, the blend of `bits`:
  // V(ω) = Σ_v bitWeight[v]·bit_v(ω), three vertices' visibility words
  // (core VisibilityBits: direction i at bit i % 32 of word i / 32), formed
  // in the pass in blendVisibility's order, so the sums are the same.
  const std::uint32_t* bits[3] = {nullptr, nullptr, nullptr};
  float bitWeight[3] = {0.0f, 0.0f, 0.0f};
  PixelDirections directions;
  // Rᵀ = R_y(−γ) R_x(−β) R_y(−α): α turns the directions, β tilts them,
  // and γ is an offset of the source column, split into a whole number of
  // columns and a fraction so the float coordinate stays small.
  float cosAlpha = 1.0f, sinAlpha = 0.0f, cosBeta = 1.0f, sinBeta = 0.0f;
  int columnShift = 0;        // whole columns of γ·M/2π + ½
  float columnFraction = 0.0f;
  float skipBelowY = -2.0f;   // directions with cos θ' below this read only zero texels
  // The rows that can reach the slices' non-zero cap (shared::passRows);
  // the pass visits only theirs.
  int firstRow = 0, endRow = 0;
  // The lobe path's core (fused.h LobePath): directions whose R_x(−β)R_y(−α)ω
  // is within it of `axis` (the lobe's axis turned by R_y(γ)), cos > coreCos,
  // read ρ = 0; they are the lobe path's. coreCos > 1: no core.
  float axisX = 0.0f, axisY = 1.0f, axisZ = 0.0f;
  float coreCos = 2.0f;
};

// out[0..2]: Σ W_c·ρ_c; out[3..5]: Σ ΔΩ·ρ_c, the lobe's energy as the map's
// directions sample it, over the rows firstRow … endRow − 1.
void fusedSample(const FusedPass& pass, float out[6]);

// The adaptive pass (shared_cells.h, fused_cells_kernel.cpp): the full
// pass's rotation, slice, rows, bits and core (`pass.light` and
// `pass.visibility` unused: V is the three vertices' bits), and what the
// cells read.
struct FusedCellPass {
  FusedPass pass;
  const CellDirections* cells = nullptr;
  const CellLight* light = nullptr;
  const float* detail[2] = {nullptr, nullptr};  // the blend's two slices' detail maps
  // The three vertices' cell masks (fused_cells.h cellMasks): V_C per cell.
  const std::uint32_t* cellMasks[3] = {nullptr, nullptr, nullptr};
  std::size_t cellMaskWords = 0;  // per set
  float tolerance = 0.0f;
  // cos(core angle + cellReach): a cell whose turned centre is nearer the
  // lobe's axis may hold core directions and is summed fine; > 1: no core.
  float coreCellCos = 2.0f;
  // shared::cellReachCut: a cell whose turned centre has y below it adds
  // nothing and is not visited.
  float reachCut = -2.0f;
};
// out as fusedSample's, over the cells of rows firstRow … endRow − 1.
void fusedSampleCells(const FusedCellPass& pass, CellScratch& scratch, float out[6], CellCounts& counts);
// ρ_c at point lights' directions (object frame), fused.comp's pointRhoAt
// for a vector of lights at a time (point_rho_kernel.cpp): the pass's turn,
// cut and core, then Catmull-Rom over 4 × 4 taps of the point slices.
struct PointRhoPass {
  const FusedPass* pass = nullptr;  // the turn (α, β), skipBelowY and the core
  int level = 0;                    // the point slices'
  int columnShift = 0;              // γ at that level (as FusedPass's)
  float columnFraction = 0.0f;
  const float* first = nullptr;     // the blend's two point slices (shared::kTexelFloats texels)
  const float* second = nullptr;
  float weight = 0.0f;
};
// At most shared::kMaxPointLights; x, y, z hold kPointLightLanes floats
// each (fused.h: whole vectors are read, what lies past n is ignored), rho
// three planes of kPointLightLanes (R, then G, then B; light j at j).
void pointRho(const PointRhoPass& pass, const float* x, const float* y, const float* z, std::size_t n, float* rho);
const char* fusedTarget();
// The target's float lanes: the pass forms V from the bits only where a
// vector's lanes lie in one word (≤ 32).
std::size_t fusedLanes();

}  // namespace haarcast::detail
