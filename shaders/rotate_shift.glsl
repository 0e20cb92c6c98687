// shiftPhi (core/rotate_spatial.cpp) for the table and matrix shaders: a pure
// φ-shift of a map given by its Haar coefficients, written as coefficients
// to the workgroup's output region. Exact (a permutation of pixels) for whole
// pixels, linear interpolation along φ otherwise, as on the CPU.
//
// Needs, before the include: rotate_common.glsl and `shared float buf[N]`.
// The map never exists as pixels: its level-(n−1) scaling values are
// synthesised in place in buf, each shifted pixel is read from them and the
// finest details, and g is analysed in place in the output region. Both
// in-place steps stage one 2×2 group per invocation in registers across a
// barrier, which needs 4^(n−2) ≤ 256 invocations: LEVEL ≤ 6.

// Pixel (r, c) of the map whose level-(n−1) scaling values sit in buf's
// top-left quadrant and whose finest details sit in their quadrant-layout
// places in buf: (s ± h ± v ± d')/2 (haar.cpp synthesisStep).
float shiftSourcePixel(uint r, uint c) {
  const uint i = r / 2u, j = c / 2u;
  const float sh = (c & 1u) == 0u ? 1.0 : -1.0, sv = (r & 1u) == 0u ? 1.0 : -1.0;
  const float s = buf[i * M + j];
  const float h = buf[i * M + HALF + j];
  const float v = buf[(HALF + i) * M + j];
  const float d = buf[(HALF + i) * M + HALF + j];
  return 0.5 * (s + sh * h + sv * v + sh * sv * d);
}

// Precondition: buf holds the map's N coefficients (quadrant layout, row
// stride M), written by this workgroup before a barrier. Destroys buf.
void shiftPhiToOutput(float radians, uint out0) {
  const uint inv = gl_LocalInvocationIndex;

  // (1) Partial synthesis in place: S_{k+1} from S_k and the level-k details,
  // which together fill exactly the [0, 2^(k+1))² square that S_{k+1}
  // replaces; up to S_{n−1}.
  for (uint k = 0u; k + 1u < LEVEL; ++k) {
    const uint blocks = 1u << k;
    const bool staged = inv < blocks * blocks;
    vec4 px = vec4(0.0);
    uint pi = 0u, pj = 0u;
    if (staged) {
      pi = inv / blocks;
      pj = inv % blocks;
      const float s = buf[pi * M + pj], h = buf[pi * M + blocks + pj];
      const float v = buf[(blocks + pi) * M + pj], d = buf[(blocks + pi) * M + blocks + pj];
      px = 0.5 * vec4(s + h + v + d, s - h + v - d, s + h - v - d, s - h - v + d);
    }
    memoryBarrierShared();
    barrier();
    if (staged) {
      buf[2u * pi * M + 2u * pj] = px.x;
      buf[2u * pi * M + 2u * pj + 1u] = px.y;
      buf[(2u * pi + 1u) * M + 2u * pj] = px.z;
      buf[(2u * pi + 1u) * M + 2u * pj + 1u] = px.w;
    }
    memoryBarrierShared();
    barrier();
  }

  // (2) The shift in pixels, reduced to [0, M): g(φ) = f(φ − shift), as in
  // shiftPhi. Per finest block of g: its four pixels, their details to the
  // output, their scaling value to the output's top-left quadrant (which no
  // finest detail occupies).
  float shift = radians / kTwoPiF * float(M);
  shift -= floor(shift / float(M)) * float(M);
  const float whole = floor(shift);
  const float frac = shift - whole;
  const uint mask = M - 1u;
  const uint back = uint(int(whole)) & mask;  // columns j − whole wrap
  for (uint q = inv; q < HALF * HALF; q += gl_WorkGroupSize.x) {
    const uint i = q / HALF, j = q % HALF;
    float g[4];
    for (uint p = 0u; p < 4u; ++p) {
      const uint r = 2u * i + p / 2u, c = 2u * j + p % 2u;
      const uint c0 = (c - back) & mask, c1 = (c - back - 1u) & mask;
      g[p] = (1.0 - frac) * shiftSourcePixel(r, c0) + frac * shiftSourcePixel(r, c1);
    }
    const uint finest = LEVEL - 1u;
    rotated[out0 + detailIndex(0u, finest, i, j)] = 0.5 * (g[0] - g[1] + g[2] - g[3]);
    rotated[out0 + detailIndex(1u, finest, i, j)] = 0.5 * (g[0] + g[1] - g[2] - g[3]);
    rotated[out0 + detailIndex(2u, finest, i, j)] = 0.5 * (g[0] - g[1] - g[2] + g[3]);
    rotated[out0 + i * M + j] = 0.5 * (g[0] + g[1] + g[2] + g[3]);
  }
  memoryBarrierBuffer();
  barrier();

  // (3) Analysis in place in the output's top-left quadrant, from S_{n−1}
  // down to the scaling coefficient: each step's details land in their
  // final quadrant-layout places (haar.cpp analysisStep).
  for (uint k = LEVEL - 1u; k >= 1u; --k) {
    const uint blocks = 1u << (k - 1u);
    const bool staged = inv < blocks * blocks;
    vec4 c = vec4(0.0);
    uint pi = 0u, pj = 0u;
    if (staged) {
      pi = inv / blocks;
      pj = inv % blocks;
      const uint tl = out0 + 2u * pi * M + 2u * pj;
      c = vec4(rotated[tl], rotated[tl + 1u], rotated[tl + M], rotated[tl + M + 1u]);
    }
    memoryBarrierBuffer();
    barrier();
    if (staged) {
      rotated[out0 + pi * M + pj] = 0.5 * (c.x + c.y + c.z + c.w);
      rotated[out0 + detailIndex(0u, k - 1u, pi, pj)] = 0.5 * (c.x - c.y + c.z - c.w);
      rotated[out0 + detailIndex(1u, k - 1u, pi, pj)] = 0.5 * (c.x + c.y - c.z - c.w);
      rotated[out0 + detailIndex(2u, k - 1u, pi, pj)] = 0.5 * (c.x - c.y - c.z + c.w);
    }
    memoryBarrierBuffer();
    barrier();
  }
}
