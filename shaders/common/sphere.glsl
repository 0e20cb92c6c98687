// Sphere-map conventions of server/core/include/haarcast/core/sphere_map.h and
// rotation.h, in float: directions, (θ, φ), bilinear taps and Y-X-Y
// rotations. Every shader that touches a map uses these, so the GPU and the
// CPU reference agree on the stencil.
#ifndef HAARCAST_SPHERE_GLSL
#define HAARCAST_SPHERE_GLSL

// kPiF and kTwoPiF, with the host's π.
#include "haarcast/core/shared_layout.h"

// ---- Transcendentals to float precision ----------------------------------
// Vulkan lets sin, cos, atan and acos be loose (sin/cos to 2^-11 absolute,
// atan/acos "inherited", thousands of ULP), and Mesa's lavapipe uses such
// approximations: measured 7e-4 relative error in a backdrop lookup. These
// are Cephes' single-precision polynomials (sinf, cosf, atanf), accurate to
// a few ULP, so every device computes the CPU's numbers to float precision.

// sin and cos of x, |x| ≲ 1e4: Cody–Waite reduction by π/2 (the three parts
// sum to π/2 and j·part1 is exact), then the quadrant's polynomial.
vec2 sinCosPrecise(float x) {
  float j = floor(x * 0.63661977236758134 + 0.5);
  float r = ((x - j * 1.5703125) - j * 4.8375129699707031e-4) - j * 7.5497899548918821e-8;
  float z = r * r;
  float s = ((-1.9515295891e-4 * z + 8.3321608736e-3) * z - 1.6666654611e-1) * z * r + r;
  float c = ((2.443315711809948e-5 * z - 1.388731625493765e-3) * z + 4.166664568298827e-2) * z * z - 0.5 * z + 1.0;
  int q = int(j) & 3;
  if (q == 0) return vec2(s, c);
  if (q == 1) return vec2(c, -s);
  if (q == 2) return vec2(-s, -c);
  return vec2(-c, s);
}
float sinPrecise(float x) { return sinCosPrecise(x).x; }
float cosPrecise(float x) { return sinCosPrecise(x).y; }

// atan2(y, x) in (−π, π], 0 for (0, 0) as C's atan2.
float atan2Precise(float y, float x) {
  float ax = abs(x), ay = abs(y);
  float hi = max(ax, ay), lo = min(ax, ay);
  float t = lo / max(hi, 1e-30);  // in [0, 1]; 0 at (0, 0), which then gives 0 (no branch: SIMD devices mask them)
  float base = 0.0;
  if (t > 0.4142135623730950) {  // tan(π/8): reduce to |t| ≤ tan(π/8)
    base = 0.78539816339744831;
    t = (t - 1.0) / (t + 1.0);
  }
  float z = t * t;
  float a = base + (((8.05374449538e-2 * z - 1.38776856032e-1) * z + 1.99777106478e-1) * z - 3.33329491539e-1) * z * t + t;
  if (ay > ax) a = 1.57079632679489662 - a;
  if (x < 0.0) a = kPiF - a;
  return y < 0.0 ? -a : a;
}

// atan2(y, x) in (−π, π], 0 for (0, 0), as the CPU's fused kernel computes
// it (core fused_kernel.cpp Atan2): one division to a ratio in [0, 1], then
// Highway's float polynomial for atan on [0, 1] (hwy/contrib/math,
// AtanImpl<float>; 3 ULP), evaluated in the same Estrin order with fused
// multiply-adds, no range reduction and no branch. Cheaper than
// atan2Precise (one division, not two) and the CPU's numbers.
float atanUnit(float x) {
  const float y = x * x;
  const float y2 = y * y, y4 = y2 * y2;
  const float p = fma(y4, fma(y2, fma(0.00282363896258175373077393, y, -0.0159569028764963150024414),
                              fma(0.0425049886107444763183594, y, -0.0748900920152664184570312)),
                      fma(y2, fma(0.106347933411598205566406, y, -0.142027363181114196777344),
                          fma(0.199926957488059997558594, y, -0.333331018686294555664062)));
  return fma(p, y * x, x);
}
float atan2Fast(float y, float x) {
  const float ay = abs(y), ax = abs(x);
  float a = atanUnit(min(ay, ax) / max(max(ay, ax), 1e-30));
  a = ay > ax ? 1.57079632679489662 - a : a;
  a = x < 0.0 ? kPiF - a : a;
  return (floatBitsToUint(y) & 0x80000000u) != 0u ? -a : a;  // the sign of y, −0 included (CopySign)
}

// acos(y), y in [−1, 1]: atan2 of sin and cos, with 1 − y² as (1 − y)(1 + y)
// so that it keeps its precision near the poles.
float acosPrecise(float y) { return atan2Precise(sqrt(max((1.0 - y) * (1.0 + y), 0.0)), y); }

// (sin θ sin φ, cos θ, sin θ cos φ): θ from +Y, φ from +Z toward +X.
vec3 sphericalToDirection(float theta, float phi) {
  vec2 t = sinCosPrecise(theta), p = sinCosPrecise(phi);
  return vec3(t.x * p.x, t.y, t.x * p.y);
}

// Inverse of the above for any non-zero vector; φ in [0, 2π).
vec2 directionToSpherical(vec3 d) {
  float len = length(d);
  float y = clamp(d.y / len, -1.0, 1.0);
  float phi = atan2Precise(d.x, d.z);
  if (phi < 0.0) phi += kTwoPiF;
  if (phi >= kTwoPiF) phi -= kTwoPiF;
  return vec2(acosPrecise(y), phi);
}

// bilinearTaps of sphere_map.cpp: rows (x, y), columns (z, w) and the
// fractions toward the second row and column. φ wraps, θ clamps at the poles.
struct Taps {
  ivec4 rc;
  vec2 t;
};
Taps bilinearTaps(int level, float theta, float phi) {
  int m = 1 << level;
  float y = clamp(theta / kPiF * float(m) - 0.5, 0.0, float(m - 1));
  float x = phi / kTwoPiF * float(m) - 0.5;
  float fy = floor(y);
  float fx = floor(x);
  Taps t;
  t.t = vec2(y - fy, x - fx);
  int r0 = int(fy);
  int jw = int(fx);
  int c0 = ((jw % m) + m) % m;
  t.rc = ivec4(r0, min(r0 + 1, m - 1), c0, (c0 + 1) % m);
  return t;
}

// R_y(a) adds a to φ: x̂ → (c, 0, −s), ẑ → (s, 0, c). R_x(b) tilts +Y toward +Z.
mat3 rotY(float a) {
  vec2 sc = sinCosPrecise(a);
  float c = sc.y, s = sc.x;
  return mat3(vec3(c, 0.0, -s), vec3(0.0, 1.0, 0.0), vec3(s, 0.0, c));
}
mat3 rotX(float b) {
  vec2 sc = sinCosPrecise(b);
  float c = sc.y, s = sc.x;
  return mat3(vec3(1.0, 0.0, 0.0), vec3(0.0, c, s), vec3(0.0, -s, c));
}
// R = R_y(α) R_x(β) R_y(γ) (rotation.h).
mat3 rotationYXY(float alpha, float beta, float gamma) { return rotY(alpha) * rotX(beta) * rotY(gamma); }

#endif
