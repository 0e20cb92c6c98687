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

#include "haarcast/core/haar.h"

namespace haarcast {

// light: Haar coefficients of L·ΔΩ, k largest kept (see keepLargest);
// brdf: dense coefficients of the rotated slice ρ·cos θᵢ (object frame);
// visibility: Haar coefficients of V (object frame), possibly truncated.
// All three must share a level (std::invalid_argument otherwise).
double tripleProduct(const SparseHaar& light, const HaarMap& brdf, const SparseHaar& visibility);

// Reference for tests: Σ over pixels of the three reconstructed maps.
double tripleProductBruteForce(const HaarMap& light, const HaarMap& brdf, const HaarMap& visibility);

}  // namespace haarcast
