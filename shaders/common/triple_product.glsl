// The triple product ∫ L·ρ·V dω in the Haar basis: a port of
// server/core/src/triple_product.cpp (Ng et al. 2004, tripling coefficient
// theorem; see triple_product.h for the three kinds of surviving terms).
//
// The light and the visibility arrive as sparse lists of blocks sorted by
// their preorder key (shared_layout.h haarPreorderKey, the CPU's order), one
// uvec4 per block: (key, h, v, d bits).
// A header uvec4 (first entry, entry count, scaling-coefficient bits, 0)
// describes each list. The BRDF is the dense rotated slice, read from a
// buffer through the macro BRDF(i), which the including shader defines.
// Requires LEVEL (the map level, ≤ 7) and shared_layout.h.
#ifndef HAARCAST_TRIPLE_PRODUCT_GLSL
#define HAARCAST_TRIPLE_PRODUCT_GLSL

const int kTpMaxLevels = 8;

// The (h, v, d) details of block (l, i, j) of the dense BRDF (the quadrant
// layout of shared_layout.h haarDetailIndex).
vec3 brdfDetails(uint base, int l, int i, int j) {
  const uint m = 1u << LEVEL;
  return vec3(BRDF(base + haarDetailIndex(m, 0u, uint(l), uint(i), uint(j))),
              BRDF(base + haarDetailIndex(m, 1u, uint(l), uint(i), uint(j))),
              BRDF(base + haarDetailIndex(m, 2u, uint(l), uint(i), uint(j))));
}

#endif
