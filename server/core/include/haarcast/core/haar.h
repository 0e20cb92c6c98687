// The non-standard (non-separable), orthonormal 2D Haar transform of a sphere
// map (DESIGN.md "Haar"), its sparse form, and non-linear approximation.
//
// For a 2×2 block with a top-left, b top-right, c bottom-left, d bottom-right:
//   s = (a+b+c+d)/2, h = (a−b+c−d)/2 (along φ), v = (a+b−c−d)/2 (along θ),
//   d' = (a−b−c+d)/2.
// The decomposition recurses on the s quadrant. Coefficients use the usual
// quadrant layout of an M×M array: the details of "detail level" l (a 2^l×2^l
// grid of blocks, each block covering 2^(n−l) pixels on a side) sit at
//   h: rows [0, 2^l),      cols [2^l, 2^(l+1))
//   v: rows [2^l, 2^(l+1)), cols [0, 2^l)
//   d: rows [2^l, 2^(l+1)), cols [2^l, 2^(l+1))
// and the single scaling coefficient at (0, 0). Detail level n−1 is the finest.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "haarcast/core/shared_layout.h"
#include "haarcast/core/sphere_map.h"

namespace haarcast {

enum class Band : std::uint8_t { Horizontal = 0, Vertical = 1, Diagonal = 2 };

// Dense Haar coefficients of a level-n map, in quadrant layout.
class HaarMap {
 public:
  HaarMap() = default;
  explicit HaarMap(int level);

  int level() const { return level_; }
  int size() const { return mapSize(level_); }
  std::size_t coefficientCount() const { return coeffs_.size(); }

  std::span<float> coefficients() { return coeffs_; }
  std::span<const float> coefficients() const { return coeffs_; }
  float& operator[](std::size_t i) { return coeffs_[i]; }
  float operator[](std::size_t i) const { return coeffs_[i]; }

  float scaling() const { return coeffs_[0]; }
  float& scaling() { return coeffs_[0]; }

  // Index into coefficients() of a detail coefficient: band, detail level l
  // (0 ≤ l < n), block row i and column j (0 ≤ i, j < 2^l).
  std::size_t detailIndex(Band band, int l, int i, int j) const {
    return detailIndexOf(size(), band, l, i, j);
  }
  float detail(Band band, int l, int i, int j) const { return coeffs_[detailIndex(band, l, i, j)]; }
  float& detail(Band band, int l, int i, int j) { return coeffs_[detailIndex(band, l, i, j)]; }

  // shared_layout.h haarDetailIndex: the layout the shaders use.
  static std::size_t detailIndexOf(int size, Band band, int l, int i, int j) {
    return shared::haarDetailIndex(static_cast<shared::uint>(size), static_cast<shared::uint>(band),
                                   static_cast<shared::uint>(l), static_cast<shared::uint>(i), static_cast<shared::uint>(j));
  }

 private:
  int level_ = 0;
  std::vector<float> coeffs_{0.0f};
};

// Where a coefficient index sits: scaling, or (band, level, i, j).
struct CoefficientPosition {
  bool isScaling = false;
  Band band = Band::Horizontal;
  int level = 0;  // detail level l
  int i = 0;      // block row
  int j = 0;      // block column
};
CoefficientPosition coefficientPosition(int mapLevel, std::size_t index);

HaarMap forwardHaar(const SphereMap& map);
SphereMap inverseHaar(const HaarMap& coeffs);

// Partial synthesis: the 2^l × 2^l scaling ("s") values of detail level l,
// i.e. the low-pass image one step coarser than the details of level l,
// reconstructed from the scaling coefficient and the details of levels < l.
// s at level l of a block is (sum of the block's pixels) / (block side).
std::vector<double> scalingValues(const HaarMap& coeffs, int l);
// The same into caller-owned buffers (resized; no allocation once they are
// large enough): out gets the 2^l × 2^l values, scratch is work space.
void scalingValues(const HaarMap& coeffs, int l, std::vector<double>& out, std::vector<double>& scratch);

// Non-zero coefficients of a map, sorted by index.
struct SparseHaar {
  int level = 0;
  std::vector<std::uint32_t> index;
  std::vector<float> value;

  std::size_t size() const { return index.size(); }
  HaarMap toDense() const;
  static SparseHaar fromDense(const HaarMap& dense);  // every non-zero
};

// Side, in pixels, of the support of the basis function at `index`.
int supportSide(int mapLevel, std::size_t index);

// Non-linear approximation (Ng et al. 2003): keep the k coefficients of
// largest area-weighted magnitude |c|·side, where side is the pixel side of
// the basis function's support — |c|·side is the L1 mass of that term, i.e. the
// most it can add to an integral against a function bounded by 1. Ties go to
// the lower index. k ≥ coefficientCount keeps all non-zeros.
SparseHaar keepLargest(const HaarMap& coeffs, std::size_t k);

}  // namespace haarcast
