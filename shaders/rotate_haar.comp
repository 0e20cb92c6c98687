// haar: the seed's Haar-domain rotation, variants Refined (the default) and
// Faithful — a float port of rotateHaar (server/core/src/rotate_haar.cpp,
// start level n−1), to which the tests compare it coefficient by coefficient.
//
// One workgroup per (sample, channel); the local size is specialization
// constant 2 (default 128), which the renderer sets per device: lavapipe runs
// every barrier() over all SIMD groups of a workgroup, so small groups win
// there (64), while a GPU wants more threads in flight (256). Steps:
//  (1) f's exact differences across every pixel boundary, fT (θ) and fP (φ).
//      They depend on the slice only, so the host derives them once per slice
//      at load time (rotation_data.cpp, by rotate_haar's own formulas) and
//      passes them in kRotateMethodDataBinding; they are not stored assets.
//  (2) g's differences by the finite chain rule: g(p₂) − g(p₁) = f(S(p₂)) −
//      f(S(p₁)) summed over the source cells the straight path crosses
//      (walk()). Invocations run over pixel boundaries: the θ-group makes
//      the vertical band's differences, the φ-group the horizontal and
//      diagonal bands', concurrently.
//  (3) The details of every level by the seed's recursive filters (eqs.
//      14–16, "Algorithmic optimization"): from one level's difference fields
//      the band's details and, by the [1 2 1] triangle and the box, the next
//      coarser level's difference fields. V, H and D and both next fields
//      are separate work items, run concurrently.
//  (4) The scaling coefficient anchored on one absolute value of f, at the
//      source of g's pixel (0, 0).
//
// Memory: shared holds the difference fields of the levels n−1 … 1 and
// faithful's 128 partial sums (at level 6, 2,605 + 128 floats = 10.7 KiB;
// LEVEL must lie in [1, 6] so that it stays under 16 KiB). The finest
// details go straight to the output and are read back once, as the
// within-block differences of the next field.
//
// Steps (1)–(4) are Refined. Faithful (the seed as written: rotateHaar's
// faithfulDifferences), chosen per object by its data block, instead takes
// each boundary difference in step (2) from the Jacobian chain rule (seed
// eqs. 11–12) with f's derivative samples read bilinearly, and the scaling
// coefficient in step (4) from the rotation-invariant ∫f dω. Step (3) is
// shared.
//
// Binding 2, per object at methodBase (rotation_data.h, RotationMethod::Haar):
//   word 0: the object's first global slice index; word 1: the variant,
//   0 refined, 1 faithful; words 2–3: zero. Refined: per θ slice t and
//   channel c, at 4 + (t·3 + c)·(2M−1)·M: fT[(M−1)·M] (row t, col c:
//   f(t+1, c) − f(t, c)) and fP[M·M] (row r, col u: f(r, u+1) − f(r, u),
//   u+1 wrapping), as floats. Faithful: the vertical moments at 4 + 2^l − 1
//   + i, then per map at 4 + (M−1) + (t·3 + c)·(1 + M²/2): ∫f dω, ∂f/∂θ and
//   ∂f/∂φ at the (M/2)² block centres.
#version 450
#extension GL_GOOGLE_include_directive : require

#include "rotate_common.glsl"

layout(local_size_x = 128, local_size_x_id = kSpecLocalSize) in;  // momentSums[] has one entry per invocation

// Σ_{k=1}^{K−1} (2^k − 1)·2^k: where the level-K field starts in `fields`.
uint fieldOffset(uint k) { return ((1u << (2u * k)) - 4u) / 3u - ((1u << k) - 2u); }

// θ-fields DT_k ((2^k − 1) rows × 2^k) for k = 1 … n−1, then φ-fields DP_k
// (2^k rows × (2^k − 1)). DT_k(a, j) is the difference, down θ, of the sums of
// the pixels of two level-k blocks (2^(n−k) pixels a side): DT_n would be
// g's pixel differences themselves. "+ 1" keeps the array non-empty at n = 1.
const uint kThetaFields = ((1u << (2u * LEVEL)) - 4u) / 3u - (M - 2u);
shared float fields[2u * kThetaFields + 1u];

uint thetaField(uint k, uint a, uint j) { return fieldOffset(k) + a * (1u << k) + j; }
uint phiField(uint k, uint i, uint b) { return kThetaFields + fieldOffset(k) + i * ((1u << k) - 1u) + b; }

// Source of g's pixel centre (r, c) in f's pixel coordinates (x along φ,
// y along θ, pixel centres at integers): Rᵀ·p as in finiteChainRule.
// Θ from atan2(ρ, y), which keeps float precision near the poles where
// acos(y) loses it.
vec2 sourcePoint(mat3 rt, uint r, uint c) {
  const vec3 s = rt * sphericalToDirection((float(r) + 0.5) * kPiF / float(M), (float(c) + 0.5) * kTwoPiF / float(M));
  float srcPhi = atan2Precise(s.x, s.z);  // directionToSpherical: φ from +Z toward +X, 0 at the poles
  if (srcPhi < 0.0) srcPhi += kTwoPiF;
  const float srcTheta = atan2Precise(length(s.xz), s.y);
  return vec2(srcPhi / kTwoPiF * float(M) - 0.5, srcTheta / kPiF * float(M) - 0.5);
}

// s at which a coordinate starting at p0 ∈ [0, 1) next crosses an integer.
float firstCrossing(float p0, float dp) {
  if (dp > 0.0) return (floor(p0) + 1.0 - p0) / dp;
  if (dp < 0.0) return (ceil(p0) - 1.0 - p0) / dp;
  return 2.0;  // never within s ∈ [0, 1]
}

// f(b) − f(a) for the bilinear f between pixel centres, along the straight
// path in (x, y), x the short way round: the finite chain rule of
// finiteChainRule's difference(). In the cell with corner (col, row),
// f = f₀ + y·fT + x·fP + xy·(fP(row+1) − fP(row)), so each piece of the path
// adds Δy·fT + Δx·fP + Δ(xy)·mixed. Beyond the first and last row centres θ
// is clamped, so there only fP of the polar row acts. Coordinates are kept
// relative to the cell of a, so that float holds their fractions.
float walk(vec2 a, vec2 b, uint fT, uint fP) {
  float dx = b.x - a.x;
  dx -= round(dx / float(M)) * float(M);
  const float dy = b.y - a.y;
  const vec2 corner = floor(a);
  const vec2 p = a - corner;
  const int col0 = int(corner.x), row0 = int(corner.y);
  const int mask = int(M) - 1;  // M is a power of two: & wraps negative columns too
  float nextX = firstCrossing(p.x, dx), nextY = firstCrossing(p.y, dy);
  const float stepX = dx != 0.0 ? 1.0 / abs(dx) : 0.0;
  const float stepY = dy != 0.0 ? 1.0 / abs(dy) : 0.0;
  float sum = 0.0, s0 = 0.0;
  // A path crosses at most M/2 + 1 columns and M + 1 rows; the bound only
  // guards against a non-finite input looping for ever.
  for (uint guard = 0u; s0 < 1.0 && guard < 2u * M + 8u; ++guard) {
    const float s1 = min(min(nextX, nextY), 1.0);
    if (s1 > s0) {
      const float sm = 0.5 * (s0 + s1);
      const float cx = floor(p.x + sm * dx), cy = floor(p.y + sm * dy);
      const uint col = uint((col0 + int(cx)) & mask);
      const int row = row0 + int(cy);
      const float x0 = p.x + s0 * dx - cx, x1 = p.x + s1 * dx - cx;
      if (row < 0 || row >= int(M) - 1) {
        sum += (x1 - x0) * uintBitsToFloat(methodData[fP + (row < 0 ? 0u : M - 1u) * M + col]);
      } else {
        const float y0 = p.y + s0 * dy - cy, y1 = p.y + s1 * dy - cy;
        const uint at = uint(row) * M + col;
        const float t = uintBitsToFloat(methodData[fT + at]);
        const float f0 = uintBitsToFloat(methodData[fP + at]);
        const float f1 = uintBitsToFloat(methodData[fP + at + M]);
        sum += (y1 - y0) * t + (x1 - x0) * f0 + (x1 * y1 - x0 * y0) * (f1 - f0);
      }
    }
    if (nextX <= s1) nextX += stepX;
    if (nextY <= s1) nextY += stepY;
    s0 = s1;
  }
  return sum;
}

// Faithful: f's derivative field at `field` ((M/2)² block-centre samples,
// θ-major) at block coordinates (y, x): bilinear, φ periodic, θ clamped
// (rotate_haar.cpp's Lattice).
float latticeSample(uint field, float y, float x) {
  y = clamp(y, 0.0, float(HALF - 1u));
  const float fy = floor(y), fx = floor(x);
  const float ty = y - fy, tx = x - fx;
  const uint r0 = uint(fy), r1 = min(r0 + 1u, HALF - 1u);
  const uint c0 = uint(int(fx) & int(HALF - 1u)), c1 = (c0 + 1u) & (HALF - 1u);
  const float top = (1.0 - tx) * methodFloat(field + r0 * HALF + c0) + tx * methodFloat(field + r0 * HALF + c1);
  const float bottom = (1.0 - tx) * methodFloat(field + r1 * HALF + c0) + tx * methodFloat(field + r1 * HALF + c1);
  return (1.0 - ty) * top + ty * bottom;
}

// Faithful: g's difference across the pixel boundary at (θ, φ) = (row·Δθ,
// col·Δφ), along θ or φ: step · (∂f/∂Θ · ∂Θ/∂x + ∂f/∂Φ · ∂Φ/∂x) at the
// source point (seed eqs. 11–12; rotate_haar.cpp's sourceWithJacobian: Θ, Φ
// of s = Rᵀp and their derivatives from s_θ = Rᵀp_θ, s_φ = Rᵀp_φ). `derivs`:
// the ∂f/∂θ samples, followed by the ∂f/∂φ samples.
float jacobianDifference(mat3 rt, float row, float col, bool alongTheta, uint derivs) {
  const uint derivTheta = derivs, derivPhi = derivs + HALF * HALF;
  const vec2 t = sinCosPrecise(row * kPiF / float(M)), p = sinCosPrecise(col * kTwoPiF / float(M));
  const vec3 s = rt * vec3(t.x * p.x, t.y, t.x * p.y);
  const vec3 ds = alongTheta ? rt * vec3(t.y * p.x, -t.x, t.y * p.y) : rt * vec3(t.x * p.y, 0.0, -t.x * p.x);
  const float rho2 = max(s.x * s.x + s.z * s.z, 1e-24), rho = sqrt(rho2);
  const float dTheta = -ds.y / rho;
  const float dPhi = (s.z * ds.x - s.x * ds.z) / rho2;
  float srcPhi = atan2Precise(s.x, s.z);
  if (srcPhi < 0.0) srcPhi += kTwoPiF;
  const float srcTheta = atan2Precise(sqrt(s.x * s.x + s.z * s.z), s.y);
  // Block centres sit at θ = (2i+1)Δθ, φ = (2j+1)Δφ.
  const float y = srcTheta / kTwoPiF * float(M) - 0.5, x = srcPhi / (2.0 * kTwoPiF) * float(M) - 0.5;
  const float step = alongTheta ? kPiF / float(M) : kTwoPiF / float(M);
  return step * (latticeSample(derivTheta, y, x) * dTheta + latticeSample(derivPhi, y, x) * dPhi);
}

// Faithful's scaling coefficient: per-invocation partial sums of Σ v·moment.
shared float momentSums[gl_WorkGroupSize.x];

void main() {
  const uint local = gl_WorkGroupID.x;
  if (local >= pushed.count) return;  // uniform over the workgroup
  const uint channel = gl_WorkGroupID.y;
  const RotationSample rs = samples[pushed.first + local];
  const uint out0 = (local * 3u + channel) * N;
  const uint sliceBase = methodData[rs.methodBase];
  const bool faithful = methodData[rs.methodBase + 1u] == 1u;  // uniform over the workgroup
  const uint theta = rs.slice - sliceBase;
  // Refined: f's difference fields.
  const uint fT = rs.methodBase + 4u + (theta * 3u + channel) * (2u * M - 1u) * M;
  const uint fP = fT + (M - 1u) * M;
  // Faithful: the moments, and the map's integral and derivative samples.
  const uint moments = rs.methodBase + 4u;
  const uint faithfulMap = moments + (M - 1u) + (theta * 3u + channel) * (1u + 2u * HALF * HALF);
  const uint derivs = faithfulMap + 1u;
  const mat3 rt = transpose(rotationYXY(rs.alpha, rs.beta, rs.gamma));
  const uint nInv = gl_WorkGroupSize.x;
  const uint finest = LEVEL - 1u;

  // (2) g's differences on pixel boundaries, per finest block (i, j) of 2×2
  // pixels. Inside the block they are the finest details (v from the two
  // θ-differences, h and d from the two φ-differences; rotate_haar.cpp's
  // triangle sums at side 2). Across to the next block down (right) they
  // start DT_{n−1}(i, j) = sT(i, j) + 2·across + sT(i+1, j), the [1 2 1]
  // triangle of the block sums; sT(i+1, j) is added in the next pass.
  for (uint q = gl_LocalInvocationIndex; q < 2u * HALF * HALF; q += nInv) {
    const bool thetaGroup = q < HALF * HALF;
    const uint blk = thetaGroup ? q : q - HALF * HALF;
    const uint i = blk / HALF, j = blk % HALF;
    if (thetaGroup) {
      // θ-differences at columns 2j, 2j+1: inside the block, and across
      // to the block below.
      float inner, across = 0.0;
      if (faithful) {
        const float r = float(2u * i), c = float(2u * j);
        inner = jacobianDifference(rt, r + 1.0, c + 0.5, true, derivs) +
                jacobianDifference(rt, r + 1.0, c + 1.5, true, derivs);
        if (i + 1u < HALF) {
          across = jacobianDifference(rt, r + 2.0, c + 0.5, true, derivs) +
                   jacobianDifference(rt, r + 2.0, c + 1.5, true, derivs);
        }
      } else {
        const vec2 p00 = sourcePoint(rt, 2u * i, 2u * j), p01 = sourcePoint(rt, 2u * i, 2u * j + 1u);
        const vec2 p10 = sourcePoint(rt, 2u * i + 1u, 2u * j), p11 = sourcePoint(rt, 2u * i + 1u, 2u * j + 1u);
        inner = walk(p00, p10, fT, fP) + walk(p01, p11, fT, fP);
        if (i + 1u < HALF) {
          const vec2 p20 = sourcePoint(rt, 2u * i + 2u, 2u * j), p21 = sourcePoint(rt, 2u * i + 2u, 2u * j + 1u);
          across = walk(p10, p20, fT, fP) + walk(p11, p21, fT, fP);
        }
      }
      rotated[out0 + detailIndex(1u, finest, i, j)] = -0.5 * inner;
      if (i + 1u < HALF) fields[thetaField(finest, i, j)] = inner + 2.0 * across;
    } else {
      // φ-differences at rows 2i (top), 2i+1 (bottom): inside the block,
      // and across to the block on the right.
      float top, bottom, across = 0.0;
      if (faithful) {
        const float r = float(2u * i), c = float(2u * j);
        top = jacobianDifference(rt, r + 0.5, c + 1.0, false, derivs);
        bottom = jacobianDifference(rt, r + 1.5, c + 1.0, false, derivs);
        if (j + 1u < HALF) {
          across = jacobianDifference(rt, r + 0.5, c + 2.0, false, derivs) +
                   jacobianDifference(rt, r + 1.5, c + 2.0, false, derivs);
        }
      } else {
        const vec2 p00 = sourcePoint(rt, 2u * i, 2u * j), p01 = sourcePoint(rt, 2u * i, 2u * j + 1u);
        const vec2 p10 = sourcePoint(rt, 2u * i + 1u, 2u * j), p11 = sourcePoint(rt, 2u * i + 1u, 2u * j + 1u);
        top = walk(p00, p01, fT, fP);
        bottom = walk(p10, p11, fT, fP);
        if (j + 1u < HALF) {
          const vec2 p02 = sourcePoint(rt, 2u * i, 2u * j + 2u), p12 = sourcePoint(rt, 2u * i + 1u, 2u * j + 2u);
          across = walk(p01, p02, fT, fP) + walk(p11, p12, fT, fP);
        }
      }
      rotated[out0 + detailIndex(0u, finest, i, j)] = -0.5 * (top + bottom);
      rotated[out0 + detailIndex(2u, finest, i, j)] = 0.5 * (bottom - top);
      if (j + 1u < HALF) fields[phiField(finest, i, j)] = top + bottom + 2.0 * across;
    }
  }
  memoryBarrierBuffer();
  memoryBarrierShared();
  barrier();

  // The neighbour's within-block sums, read back from its finest details:
  // sT = −2v, sP = −2h (exact in float).
  const uint across = (HALF - 1u) * HALF;
  for (uint q = gl_LocalInvocationIndex; q < 2u * across; q += nInv) {
    if (q < across) {
      const uint i = q / HALF, j = q % HALF;
      fields[thetaField(finest, i, j)] -= 2.0 * rotated[out0 + detailIndex(1u, finest, i + 1u, j)];
    } else {
      const uint i = (q - across) / (HALF - 1u), j = (q - across) % (HALF - 1u);
      fields[phiField(finest, i, j)] -= 2.0 * rotated[out0 + detailIndex(0u, finest, i, j + 1u)];
    }
  }
  memoryBarrierShared();
  barrier();

  // (3) Level k's fields → the details of level k−1 and the fields of
  // level k−1 (triangleBoxSums / triangleTriangleSums, one level at a time):
  //   v = −(DT(2a, 2b) + DT(2a, 2b+1))/side,  h = −(DP(2a, 2b) + DP(2a+1, 2b))/side,
  //   d' = (DP(2a+1, 2b) − DP(2a, 2b))/side   (the θ-difference of the
  //   φ-differences: the seed's cross-derivative), side = M/2^(k−1) pixels;
  //   DT_{k−1}(a, j) = Σ_q DT(2a, 2j+q) + 2·DT(2a+1, 2j+q) + DT(2a+2, 2j+q),
  //   and DP_{k−1} the same across φ.
  for (uint k = finest; k >= 1u; --k) {
    const uint l = k - 1u, blocks = 1u << l, cells = blocks * blocks;
    const float side = float(M >> l);
    const uint nextFields = k >= 2u ? (blocks - 1u) * blocks : 0u;
    for (uint q = gl_LocalInvocationIndex; q < 3u * cells + 2u * nextFields; q += nInv) {
      if (q < 3u * cells) {
        const uint band = q / cells, a = (q % cells) / blocks, b = q % blocks;
        float value;
        if (band == 1u) {
          value = -(fields[thetaField(k, 2u * a, 2u * b)] + fields[thetaField(k, 2u * a, 2u * b + 1u)]);
        } else {
          const float top = fields[phiField(k, 2u * a, 2u * b)], bottom = fields[phiField(k, 2u * a + 1u, 2u * b)];
          value = band == 0u ? -(top + bottom) : bottom - top;
        }
        rotated[out0 + detailIndex(band, l, a, b)] = value / side;
      } else if (q < 3u * cells + nextFields) {
        const uint r = q - 3u * cells, a = r / blocks, j = r % blocks;
        float sum = 0.0;
        for (uint c = 2u * j; c < 2u * j + 2u; ++c)
          sum += fields[thetaField(k, 2u * a, c)] + 2.0 * fields[thetaField(k, 2u * a + 1u, c)] +
                 fields[thetaField(k, 2u * a + 2u, c)];
        fields[thetaField(l, a, j)] = sum;
      } else {
        const uint r = q - 3u * cells - nextFields, i = r / (blocks - 1u), b = r % (blocks - 1u);
        float sum = 0.0;
        for (uint row = 2u * i; row < 2u * i + 2u; ++row)
          sum += fields[phiField(k, row, 2u * b)] + 2.0 * fields[phiField(k, row, 2u * b + 1u)] +
                 fields[phiField(k, row, 2u * b + 2u)];
        fields[phiField(l, i, b)] = sum;
      }
    }
    memoryBarrierBuffer();
    memoryBarrierShared();
    barrier();
  }

  // (4) The scaling coefficient. g(0, 0) = f at the source of g's first
  // pixel (bilinear, as the anchor of finiteChainRule), and pixel (0, 0) sits
  // in the + quarter of every basis function, so
  //   g(0, 0) = c₀/M + Σ_l (h + v + d')_l(0, 0) / side_l
  //   ⇒ c₀ = M·g(0, 0) − Σ_l 2^l (h + v + d')_l(0, 0).
  // This equals the CPU's mean of the integrated pixel values: both sum the
  // same differences from the same anchor.
  if (faithful) {
    // No absolute value is known: ∫g dω = ∫f dω = c₀·4π/M + Σ v·⟨ψ_v, ΔΩ⟩
    // (only the scaling and vertical functions have solid-angle moments).
    float partial = 0.0;
    for (uint l = 0u; l < LEVEL; ++l) {
      const uint blocks = 1u << l;
      for (uint q = gl_LocalInvocationIndex; q < blocks * blocks; q += nInv) {
        const uint i = q / blocks, j = q % blocks;
        partial += rotated[out0 + detailIndex(1u, l, i, j)] * methodFloat(moments + blocks - 1u + i);
      }
    }
    momentSums[gl_LocalInvocationIndex] = partial;
    memoryBarrierShared();
    barrier();
    if (gl_LocalInvocationIndex == 0u) {
      float rest = 0.0;
      for (uint q = 0u; q < nInv; ++q) rest += momentSums[q];
      rotated[out0] = (methodFloat(faithfulMap) - rest) * float(M) / (4.0 * kPiF);
    }
  } else if (gl_LocalInvocationIndex == 0u) {
    const vec2 p0 = sourcePoint(rt, 0u, 0u);
    const float y0 = clamp(p0.y, 0.0, float(M - 1u));
    const uint r0 = min(uint(y0), M - 2u);
    const uint c0 = uint(int(floor(p0.x)) & (int(M) - 1));
    const float tx = p0.x - floor(p0.x), ty = y0 - float(r0);
    const uint at = r0 * M + c0;
    const float f0 = uintBitsToFloat(methodData[fP + at]);
    const float anchor = slicePixel(rs.slice * 3u * N + channel * N, r0, c0) +
                         ty * uintBitsToFloat(methodData[fT + at]) + tx * f0 +
                         tx * ty * (uintBitsToFloat(methodData[fP + at + M]) - f0);
    float scaling = float(M) * anchor;
    for (uint l = 0u; l < LEVEL; ++l) {
      const float corner = rotated[out0 + detailIndex(0u, l, 0u, 0u)] + rotated[out0 + detailIndex(1u, l, 0u, 0u)] +
                           rotated[out0 + detailIndex(2u, l, 0u, 0u)];
      scaling -= float(1u << l) * corner;
    }
    rotated[out0] = scaling;
  }
}
