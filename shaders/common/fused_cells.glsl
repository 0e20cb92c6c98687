// `fused` by cells (core/shared_cells.h; the CPU's core/src/fused_cells_kernel.cpp):
// sumCells, step 1 of fused.comp for an object with ObjectInfo::sumTolerance
// > 0. Included by fused.comp after what it reads: the bindings (texels,
// light, visibilityBits, directions, details), LOCAL and CELLS_TOGETHER,
// PixelSetup, and turned, positionOf, bilinearAt and rhoAt.
#ifndef HAARCAST_FUSED_CELLS_GLSL
#define HAARCAST_FUSED_CELLS_GLSL

// The visibility of cell q for the vertex whose word 0 is `base`: its 16
// bits (shared_cells.h cellBits).
uint cellBitsOf(uint base, uint m, uint q) {
  return cellBits(texelFetch(visibilityBits, int(base + cellWordIndex(m, q, 0u))).r,
                  texelFetch(visibilityBits, int(base + cellWordIndex(m, q, 1u))).r,
                  texelFetch(visibilityBits, int(base + cellWordIndex(m, q, 2u))).r,
                  texelFetch(visibilityBits, int(base + cellWordIndex(m, q, 3u))).r, cellShift(m, q));
}

// V at a cell's direction k from its vertices' 16 bits, blendVisibility's order.
float cellV(PixelSetup p, uvec3 bits, uint k) {
  return p.sh.b[0] * float((bits.x >> k) & 1u) + p.sh.b[1] * float((bits.y >> k) & 1u) + p.sh.b[2] * float((bits.z >> k) & 1u);
}

// A cell's coarse work, and what it leaves: kCellFine or kCellMixed when its
// 16 directions are still to be summed (by the invocation alone, or by its
// subgroup together), kCellDone when nothing is left.
const uint kCellDone = 0u, kCellFine = 1u, kCellMixed = 2u;
uint coarseCell(const bool blended, PixelSetup p, uint q, uvec3 bits, inout vec3 acc, inout vec3 norm, inout uint counted) {
  const float v = cellVisibility(bits.x, bits.y, bits.z, p.sh.b[0], p.sh.b[1], p.sh.b[2]);
  const vec4 centre = texelFetch(directions, int(p.directionBase + cellCentreTexel(p.m, q)));  // xyz, and w = Ω_C
  const vec3 t = turned(p, centre.xyz);
  if (t.y < p.reachCut) return kCellDone;  // wholly below the cut: it adds nothing
  const vec2 pos = positionOf(t, p.m, p.fraction);
  const uint texel = detailTexel(p.m, pos.x, pos.y, p.shift);
  const float detail = max(texelFetch(details, int(p.detail0 + texel)).r, texelFetch(details, int(p.detail1 + texel)).r);
  if (detail > p.tolerance || dot(t, p.axis) > p.coreCellCos) {
    counted += 1u << 16u;
    return kCellFine;
  }
  norm += centre.w * bilinearAt(blended, p, pos);
  counted += 1u;
  if (v > 0.0) {
    const vec3 power = texelFetch(light, int(p.lightBase + cellPowerTexel(p.m, q))).rgb;
    const vec3 toward = texelFetch(light, int(p.lightBase + cellCentroidTexel(p.m, q))).xyz;
    acc += v * power * bilinearAt(blended, p, positionOf(turned(p, toward), p.m, p.fraction));
  }
  return v < 0.0 ? kCellMixed : kCellDone;
}

// Direction k of cell q: fine, its term of the full sum (acc, norm); mixed,
// its V·L and V·L-weighted direction (power, toward).
void cellDirectionTerm(const bool blended, PixelSetup p, uint q, uvec3 bits, uint kind, uint k, inout vec3 acc,
                       inout vec3 norm, inout vec3 power, inout vec3 toward) {
  const uint i = cellDirection(p.m, q, k);
  const vec4 dir = texelFetch(directions, int(p.directionBase + i));
  const vec3 l = texelFetch(light, int(p.lightBase + i)).rgb * cellV(p, bits, k);
  if (kind == kCellFine) {
    const vec3 rho = rhoAt(blended, p, dir.xyz);
    norm += dir.w * rho;
    acc += l * rho;
  } else {
    power += l;
    toward += (l.r + l.g + l.b) * dir.xyz;
  }
}

// ρ at the centroid of a mixed cell's V·L, times its V·L.
vec3 mixedTerm(const bool blended, PixelSetup p, vec3 power, vec3 toward) {
  return power * bilinearAt(blended, p, positionOf(turned(p, toward), p.m, p.fraction));
}

// 1, by cells (shared_cells.h; core fused_cells_kernel.cpp): Σ over the
// cells of the pass's rows, invocation lid taking cells q ≡ lid mod LOCAL.
// ρ at each cell's turned centre gives Ω_C·ρ and the detail there; a cell
// with detail above the tolerance, or near the lobe path's core, is summed
// direction by direction as sumDirections sums; the others at one
// direction: V_C·P_c·ρ at the light's centroid where each vertex sees all
// of it or none, Σ(V·L)·ρ at the centroid of V·L where some sees part.
// With CELLS_TOGETHER the cells left with 16 directions to sum are taken
// by the whole subgroup, one at a time, its lanes across the directions:
// a lane's own would keep the others waiting 16 steps (divergence).
// `counted`: the coarse cells in its low 16 bits, the fine in its high (a
// map has at most 1,024 cells, so the workgroup's sum keeps them apart).
vec3 sumCells(const bool blended, PixelSetup p, out vec3 norm, out uint counted) {
  vec3 acc = vec3(0.0);
  norm = vec3(0.0);
  counted = 0u;
  const uint across = cellsAcross(p.m);
  const uint r0 = p.firstRow / kCellSide, r1 = min(across, (p.endRow + kCellSide - 1u) / kCellSide);
  const uint begin = r0 * across, end = r1 * across;
  // Rounds of LOCAL cells: the trip count is the workgroup's, so a
  // subgroup's lanes stay together for the subgroup operations below.
  for (uint base = begin; base < end; base += LOCAL) {
    const uint q = base + gl_LocalInvocationID.x;
    uint kind = kCellDone;
    uvec3 bits = uvec3(0u);
    if (q < end) {
      bits = uvec3(cellBitsOf(p.bits0, p.m, q), cellBitsOf(p.bits1, p.m, q), cellBitsOf(p.bits2, p.m, q));
      kind = coarseCell(blended, p, q, bits, acc, norm, counted);
    }
    if (CELLS_TOGETHER == 0u) {
      if (kind == kCellDone) continue;
      vec3 power = vec3(0.0), toward = vec3(0.0);
      [[dont_unroll]] for (uint k = 0u; k < kCellDirections; ++k) cellDirectionTerm(blended, p, q, bits, kind, k, acc, norm, power, toward);
      if (kind == kCellMixed) acc += mixedTerm(blended, p, power, toward);
      continue;
    }
    uvec4 pending = subgroupBallot(kind != kCellDone);
    while (subgroupBallotBitCount(pending) > 0u) {
      const uint owner = subgroupBallotFindLSB(pending);
      const uint qo = subgroupShuffle(q, owner);
      const uint ko = subgroupShuffle(kind, owner);
      const uvec3 bo = uvec3(subgroupShuffle(bits.x, owner), subgroupShuffle(bits.y, owner), subgroupShuffle(bits.z, owner));
      vec3 power = vec3(0.0), toward = vec3(0.0);
      for (uint k = gl_SubgroupInvocationID; k < kCellDirections; k += gl_SubgroupSize) {
        cellDirectionTerm(blended, p, qo, bo, ko, k, acc, norm, power, toward);
      }
      if (ko == kCellMixed) {
        power = subgroupAdd(power);
        toward = subgroupAdd(toward);
        if (subgroupElect()) acc += mixedTerm(blended, p, power, toward);
      }
      pending[owner / 32u] &= ~(1u << (owner % 32u));
    }
  }
  return acc;
}

#endif  // HAARCAST_FUSED_CELLS_GLSL
