// What `fused`'s adaptive sum (shared_cells.h) reads besides the full sum's
// inputs: the map's directions in cell order with each cell's centre, the
// light per cell (its sum and centroid), and each slice's detail map.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace haarcast {

class VisibilityBits;

// A level's map directions in cell order (direction k of cell q at
// q·16 + k, shared::cellDirection), and per cell its centre: the
// ΔΩ-weighted mean of its 16 directions, normalised, and Ω_C = Σ ΔΩ.
// The per-cell arrays hold kCellPadding zeros past the last cell, so a
// vector of cells starting at any cell stays inside them.
inline constexpr std::size_t kCellPadding = 16;
struct CellDirections {
  std::vector<float> x, y, z, solidAngle;            // N each, cell order
  std::vector<float> centreX, centreY, centreZ, cellSolidAngle;  // one per cell, padded
};
// Built once per level ≥ shared::kCellMinLevel that `fused` takes
// (thread-safe static initialisation); throws std::invalid_argument below it.
const CellDirections& cellDirections(int level);

// One object's light for one frame in cell form (FusedLight::cells):
// the three planes of L_c·ΔΩ in cell order, and per cell P_c = Σ L_c·ΔΩ
// and ω̄, the centroid of its directions weighted by L_R + L_G + L_B
// (normalised; the cell's centre where the cell is black).
struct CellLight {
  int level = 0;
  std::vector<float> planes;                     // 3·N, channel c at c·N, cell order
  std::size_t stride = 0;                        // K + kCellPadding
  std::vector<float> power;                      // channel c's K at c·stride, padded
  std::vector<float> centroidX, centroidY, centroidZ;  // K each, padded
  // From row-major planes of L·ΔΩ (FusedLight::planes) at `level` ≥ kCellMinLevel.
  static CellLight fromPlanes(int level, std::span<const float> rowMajorPlanes);
};

// Which cells of a point's map it sees whole, and which it sees any of
// (shared_cells.h: what V_C is made of): two sets of K bits, cell q at bit
// q % 32 of word q / 32, the "whole" set first. Each set has one zero word
// past its last, so that the 32 cells from any cell on are two of its words.
std::size_t cellMaskWords(int level);  // per set: K/32 + 1
// From one point's visibility words (core VisibilityBits) into `out`
// (2·cellMaskWords(level) words).
void cellMasks(const std::uint32_t* words, int level, std::uint32_t* out);
// Every point's masks, built once from its bits (as WeightedBits::cells
// reads them).
class CellVisibility {
 public:
  CellVisibility() = default;
  static CellVisibility fromBits(const VisibilityBits& bits);
  bool empty() const { return masks_.empty(); }
  const std::uint32_t* point(std::size_t p) const;

 private:
  std::size_t points_ = 0;
  std::size_t wordsPerPoint_ = 0;
  std::vector<std::uint32_t> masks_;
};

// Per-thread working memory of the adaptive pass (in FusedScratch).
struct CellScratch {
  // The three vertices' masks where the caller gave none (cellMasks).
  std::vector<std::uint32_t> masks;
  std::vector<std::uint32_t> fine;   // the cells summed fine
  std::vector<std::uint32_t> mixed;  // the mixed cells summed coarse
  // Per mixed cell: Σ V·L_c·ΔΩ (three planes) and the centroid of its
  // directions weighted by V·(L_R + L_G + L_B)·ΔΩ.
  std::vector<float> mixedPower, mixedX, mixedY, mixedZ;
  // The cells that can reach the slice's non-zero cap, in order: their
  // indices, and per cell (planes of the same stride) the turned centre,
  // Ω_C, V_C, P_c and the light's centroid (fused_cells_kernel.cpp).
  std::vector<std::uint32_t> reaching;
  std::vector<float> reachingData;
};
// What one adaptive pass did.
struct CellCounts {
  std::size_t coarse = 0;  // cells summed at one direction (hidden and mixed ones too)
  std::size_t mixed = 0;   // of them, those whose V varies: their V·L summed first
  std::size_t fine = 0;    // cells summed direction by direction
};

// The detail map of one slice (shared_cells.h): per texel of the cell level
// (M/4 × M/4), how far the mean of ρ over a cell of the map differs from ρ
// at the cell's centre when the centre falls in or beside that texel,
// divided by the slice's mean over the hemisphere (max_c E_c/2π). That
// difference is what a coarse cell gets wrong under a uniform light; the
// light's own variation inside a cell the centroid takes to first order.
// Measured with the widest cell (the map's equator) centred on the texel's
// centre and on its corners, so for a cell centred anywhere in it, turned
// 0 and 90° about that point, on the bilinear lookup the pass uses, the
// largest channel taken. (Taking each texel's 3 × 3 neighbourhood's largest
// besides made 60 % more directions a sample on the default scene and the
// frames no closer to the full sum.)
// `texels`: the slice in pixel form (RGB0 texels, PixelSlices layout).
std::vector<float> sliceDetail(const float* texels, int level, const float energy[3]);

}  // namespace haarcast
