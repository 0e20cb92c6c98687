// The triple product ∫ L·ρ·V dω in the orthonormal Haar basis
// (Ng, Ramamoorthi, Hanrahan 2004; DESIGN.md "Triple product").
//
// With the solid angle folded into the light (L·ΔΩ, DESIGN.md "Solid
// angle"), Σ_pixels (L·ΔΩ)·ρ·V = Σ_ijk C_ijk a_i b_j c_k, and by the tripling
// coefficient theorem only three kinds of terms survive (discrete,
// orthonormal normalisation; a block of side s pixels):
//   1. all three scaling:                       a₀b₀c₀ / M
//   2. three different wavelet types, one block: (1/s)(a_h b_v c_d + 5 perms)
//   3. two identical wavelets, third coarser:    (1/s)·a_t b_t·S_c(block), …
// where S_c(block) is c's scaling value of that block, built from c's coarser
// coefficients along the path from the root (O(log N)). Every term needs a
// non-zero coefficient of at least two functions on the same block, so with a
// dense BRDF it suffices to visit the blocks where the light or the visibility
// is non-zero: O((k_L + k_V) log N), not a dense loop.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "haarcast/core/haar.h"

namespace haarcast {

// light: Haar coefficients of L·ΔΩ, k largest kept (see keepLargest);
// brdf: dense coefficients of the rotated slice ρ·cos θᵢ (object frame);
// visibility: Haar coefficients of V (object frame), possibly truncated.
// All three must share a level (std::invalid_argument otherwise).
double tripleProduct(const SparseHaar& light, const HaarMap& brdf, const SparseHaar& visibility);

// ---- The per-pixel path: operands prepared once ------------------------------
//
// The walk visits the blocks where the light or the visibility has a detail
// in pre-order of the block quadtree, so that one root-to-block path, updated
// incrementally, gives every block's scaling values. tripleProduct above
// validates both sparse operands, works out where each coefficient sits and
// sorts them into that order on every call. Per frame the light of an object
// and channel is one list; per pixel the visibility is one list shared by the
// three channels. Prepared once each, the walk only merges two sorted block
// lists: no allocation, validation or sort per call, and the same number
// (tripleProduct is this walk with both operands prepared per call).

// A sparse Haar function in the order the walk visits it: validated, its
// detail coefficients grouped per block (h, v, d' together) and the blocks in
// pre-order of the block quadtree (a block before its descendants).
class PreparedSparseHaar {
 public:
  struct Block {
    std::uint64_t key = 0;          // pre-order position
    int level = 0, i = 0, j = 0;    // detail level, block row and column
    std::array<double, 3> details{};  // h, v, d' (zero where x has none)
  };

  PreparedSparseHaar() = default;
  explicit PreparedSparseHaar(const SparseHaar& x, const char* what = "sparse operand") { assign(x, what); }

  // Replaces the contents with x, reusing this object's buffers (no
  // allocation once they are large enough). Throws std::invalid_argument for
  // a level outside [0, kMaxLevel], index/value counts that differ, or an
  // index outside the map; `what` names x in the message. Duplicate indices:
  // the last value counts, as in tripleProduct.
  void assign(const SparseHaar& x, const char* what = "sparse operand");

  int level() const { return level_; }
  double scaling() const { return scaling_; }  // coefficient 0 (zero if absent)
  std::span<const Block> blocks() const { return blocks_; }

 private:
  int level_ = 0;
  double scaling_ = 0.0;
  std::vector<Block> blocks_;
  std::vector<std::uint64_t> order_;  // sort buffer
};

// The light of one object and channel for one frame (L·ΔΩ, k largest kept).
using PreparedLight = PreparedSparseHaar;
// One pixel's (merged) visibility, shared by its three channels.
using PreparedVisibility = PreparedSparseHaar;

// tripleProduct with prepared operands. Throws std::invalid_argument unless
// the three share a level (the only check left per call).
double tripleProduct(const PreparedLight& light, const HaarMap& brdf, const PreparedVisibility& visibility);

// The same with the visibility as a SparseHaar, prepared into `scratch` (kept
// by the caller, one per thread). Prefer preparing the visibility once per
// pixel when the three channels share it.
struct TripleProductScratch {
  PreparedVisibility visibility;
};
double tripleProduct(const PreparedLight& light, const HaarMap& brdf, const SparseHaar& visibility,
                     TripleProductScratch& scratch);

// The visibility at a point of a triangle: Σ_v weights[v]·vertices[v], the
// barycentric blend of the three vertices' sparse lists, written into `out`
// as their union sorted by index (out's buffers are reused: no allocation once
// they are large enough). The triple product is linear in V, so one product
// with this list equals the weighted sum of the three vertices' products
// (up to the float rounding of the stored sums). A vertex of weight 0 is
// skipped. Throws std::invalid_argument for a null list, lists of different
// levels, index/value counts that differ, or indices not strictly increasing.
void mergeVisibility(const std::array<const SparseHaar*, 3>& vertices, const std::array<double, 3>& weights,
                     SparseHaar& out);

// Reference for tests: Σ over pixels of the three reconstructed maps.
double tripleProductBruteForce(const HaarMap& light, const HaarMap& brdf, const HaarMap& visibility);

}  // namespace haarcast
