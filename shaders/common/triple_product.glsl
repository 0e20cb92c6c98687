// The triple product ∫ L·ρ·V dω in the Haar basis: a port of
// server/core/src/triple_product.cpp (Ng et al. 2004, tripling coefficient
// theorem; see triple_product.h for the three kinds of surviving terms).
//
// The light and the visibility arrive as sparse lists of blocks sorted in the
// CPU's pre-order (preorderKey), one uvec4 per block: (key, h, v, d bits).
// A header uvec4 (first entry, entry count, scaling-coefficient bits, 0)
// describes each list. The BRDF is the dense rotated slice, read from a
// buffer through the macro BRDF(i), which the including shader defines.
// Requires LEVEL (the map level, ≤ 7).
#ifndef HAARCAST_TRIPLE_PRODUCT_GLSL
#define HAARCAST_TRIPLE_PRODUCT_GLSL

const int kTpMaxLevels = 8;

// Signs of (h, v, d) in the synthesis of child quadrant 2·rowBit + colBit.
vec3 childSign(int quadrant) {
  if (quadrant == 0) return vec3(1.0, 1.0, 1.0);
  if (quadrant == 1) return vec3(-1.0, 1.0, -1.0);
  if (quadrant == 2) return vec3(1.0, -1.0, -1.0);
  return vec3(-1.0, -1.0, 1.0);
}

// The (h, v, d) details of block (l, i, j) of the dense BRDF (haar.h layout).
vec3 brdfDetails(uint base, int l, int i, int j) {
  const int m = 1 << LEVEL;
  int half_ = 1 << l;
  return vec3(BRDF(base + uint(i * m + j + half_)), BRDF(base + uint((i + half_) * m + j)),
              BRDF(base + uint((i + half_) * m + j + half_)));
}

#endif
