// The adaptive sum of `fused` (docs/design.md, "A pixel's cost follows what
// it shows"), written once for the CPU kernel and the shader (C++ and GLSL,
// shared_language.h).
//
// At level n ≥ kCellMinLevel the M² map directions are grouped in cells of
// 4 × 4: cell (R, C) holds rows 4R … 4R + 3 and columns 4C … 4C + 3, cell
// index q = R·(M/4) + C, its direction k (0 … 15) at row 4R + k/4 and column
// 4C + k%4. Per pixel a cell is summed fine or coarse:
//   fine     where the slice has detail there (its detail map at the cell's
//            turned centre above the tolerance) or the lobe path's core is
//            near: the 16 directions, as the full sum takes them;
//   coarse   otherwise, at one direction, as V allows:
//            hidden  V is 0 over the cell (each vertex sees none of it):
//                    no light term;
//            whole   each vertex sees all of it or none, so V is one number
//                    V_C = Σ_v b_v·open_v: V_C·Σ_c P_c·ρ_c(Rᵀω̄), P the
//                    cell's L·ΔΩ summed and ω̄ its light-weighted centroid
//                    (exact when ρ is linear over the cell);
//            mixed   Σ_c (Σ V·L_c·ΔΩ)·ρ_c at the centroid of V·L, the 16
//                    directions' V and L summed first.
// Every cell that is not fine adds Ω_C·ρ(Rᵀω_C) (its solid angle at its
// centre) to the lobe's sampled energy, so `fused`'s energy ratio
// (fused.cpp energyKept) still divides like by like.
#ifndef HAARCAST_CORE_SHARED_CELLS_H
#define HAARCAST_CORE_SHARED_CELLS_H

#include "haarcast/core/shared_language.h"

#ifdef __cplusplus
namespace haarcast::shared {
#endif

HC_CONST uint kCellSide = 4u;
HC_CONST uint kCellDirections = 16u;
HC_CONST uint kCellAll = 0xFFFFu;  // the 16 bits of a cell every direction of which is seen
// Below level 5 a map has at most 256 directions: every one is summed.
HC_CONST uint kCellMinLevel = 5u;
// RenderOptions::sumTolerance's default: a cell is summed coarse where the
// slice's detail there (PixelSlices::detail) is at most this fraction of
// the slice's mean value over the hemisphere (docs/design.md has the bound).
HC_CONST float kDefaultSumTolerance = 0.1f;

// Whether `fused` sums a map of this level by cells (a tolerance of 0 sums
// every direction).
HC_FUNCTION bool sumsByCells(uint level, float tolerance) { return level >= kCellMinLevel && tolerance > 0.0f; }

// Cells across a map of M = m (and down it).
HC_FUNCTION uint cellsAcross(uint m) { return m / kCellSide; }

// Map direction (row-major, row·M + column) of direction k of cell q.
HC_FUNCTION uint cellDirection(uint m, uint q, uint k) {
  const uint across = cellsAcross(m);
  const uint row = (q / across) * kCellSide + k / kCellSide;
  const uint column = (q % across) * kCellSide + k % kCellSide;
  return row * m + column;
}

// One vertex's visibility (row-major bits, direction i at bit i % 32 of word
// i / 32: core VisibilityBits) over cell q as 16 bits, bit k for the cell's
// direction k: the cell's four nibbles, one word of each of its rows (a row
// is M/32 ≥ 1 whole words at level ≥ 5, and a cell's four columns never
// straddle two). `word(r)` is that row's word; the caller fetches them.
HC_FUNCTION uint cellWordIndex(uint m, uint q, uint k4) {
  const uint across = cellsAcross(m);
  const uint row = (q / across) * kCellSide + k4;
  return (row * m + (q % across) * kCellSide) / 32u;
}
HC_FUNCTION uint cellShift(uint m, uint q) { return ((q % cellsAcross(m)) * kCellSide) & 31u; }
HC_FUNCTION uint cellBits(uint w0, uint w1, uint w2, uint w3, uint shift) {
  return ((w0 >> shift) & 15u) | (((w1 >> shift) & 15u) << 4u) | (((w2 >> shift) & 15u) << 8u) |
         (((w3 >> shift) & 15u) << 12u);
}

// V over a cell from the three vertices' 16 bits and barycentric weights:
// V_C when each vertex sees all of it or none (V = b0·open0 + b1·open1 +
// b2·open2, blendVisibility's order), −1 where a vertex with a non-zero
// weight sees part of it (the cell is summed fine).
HC_FUNCTION float cellVisibility(uint bits0, uint bits1, uint bits2, float b0, float b1, float b2) {
  const bool mixed = (b0 != 0.0f && bits0 != 0u && bits0 != kCellAll) || (b1 != 0.0f && bits1 != 0u && bits1 != kCellAll) ||
                     (b2 != 0.0f && bits2 != 0u && bits2 != kCellAll);
  if (mixed) return -1.0f;
  float v = 0.0f;
  v += bits0 == kCellAll ? b0 : 0.0f;
  v += bits1 == kCellAll ? b1 : 0.0f;
  v += bits2 == kCellAll ? b2 : 0.0f;
  return v;
}

// Every direction of a cell of a level-`level` map lies within this angle of
// the cell's centre: half the diagonal of the widest cell, at the equator
// (4 rows of π/M by 4 columns of 2π/M: 2π·√5/M), with a margin for the
// centre's pull toward the cell's wider rows (SharedCells.CellReach measures it).
HC_FUNCTION float cellReach(uint m) { return 10.6f / float(m); }

// The y below which a cell's turned centre puts the whole cell below the
// pass's cut skipBelowY (core fused_kernel.h FusedPass): every direction
// within cellReach of the centre, and so every centroid of them, then reads
// only zero texels, and the cell adds nothing. A cut below the equator
// only (skipBelowY < 0: a centroid of directions below it is below it
// too); −2 where there is none: every cell is visited.
HC_FUNCTION float cellReachCut(uint m, float skipBelowY) {
  if (!(skipBelowY < 0.0f && skipBelowY > -1.0f)) return -2.0f;
  return HC_SIN(1.57079632679f - min(HC_ACOS(skipBelowY) + cellReach(m), 3.14159265f));
}

// The Vulkan backend keeps every slice's detail map at a stride of the
// most cells a map has (M/4 × M/4 at shared::kFusedMaxLevel = 7): global
// slice s's at s·kCellDetailStride.
HC_CONST uint kCellDetailStride = 1024u;

// Where the Vulkan backend keeps an object's light by cells, after its N
// texels of L·ΔΩ at its light base: P_c of cell q (RGB) at N + q, and the
// centroid of its light at N + K + q (K cells).
HC_FUNCTION uint cellPowerTexel(uint m, uint q) { return m * m + q; }
HC_FUNCTION uint cellCentroidTexel(uint m, uint q) { return m * m + cellsAcross(m) * cellsAcross(m) + q; }
// And its direction table, after its N pixel centres: cell q's centre and Ω_C at N + q.
HC_FUNCTION uint cellCentreTexel(uint m, uint q) { return m * m + q; }

// The slice's detail map is one value per texel of the cell level (M/4 ×
// M/4), read at the texel holding the turned cell centre: continuous slice
// texel position (row, column before γ's whole columns, as the pass's
// lookup forms them) → the detail texel.
HC_FUNCTION uint detailTexel(uint m, float rowPos, float colPos, int columnShift) {
  const uint row = min(uint(max(rowPos + 0.5f, 0.0f)), m - 1u);
  const uint column = uint((int(floor(colPos + 0.5f)) - columnShift) & int(m - 1u));
  return (row / kCellSide) * cellsAcross(m) + column / kCellSide;
}

#ifdef __cplusplus
}  // namespace haarcast::shared
#endif

#endif  // HAARCAST_CORE_SHARED_CELLS_H
