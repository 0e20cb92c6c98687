// `fused`'s sum taken from a pixel's neighbours where the image shows it is
// smooth (docs/design.md, "Where the sum is smooth across the image"),
// written once for the CPU backend (cpu_backend.cpp) and fused.comp (C++
// and GLSL, shared_language.h).
//
// The pass's sum (the light's rest × V × ρ, the lobe's energy put back:
// core/fused.h FusedSum) changes slowly across a surface wherever the lobe
// is wider than a pixel's turn and V has no edge; what a pixel shows
// sharply — the point lights and their shadows, the sky other objects hide,
// the lobe path's mirror core — is not in it and stays each pixel's own.
// So the frame's pixels are visited coarse to fine, in the order of
// adaptive image subdivision, in kSmoothSumStages stages: stage 0 sums every
// pixel of a grid kSmoothSumSpacing apart; then, halving the step, each
// midpoint of the grid's edges (Edges: two parents, across or down) and each
// centre of its squares (Centres: four parents, the midpoints just done)
// takes its parents' mean sum where
//   - each parent's mirror direction is within kSmoothSumLobeShare of the
//     object's sharpest median lobe angle of the pixel's (the sum is the
//     light blurred by the lobe: smooth only where the mirror directions
//     move by less than the lobe is wide; a near-mirror's sum, sampled by
//     the map's directions, changes from pixel to pixel more than its
//     neighbours' agreement can show), and
//   - their sums agree (smoothSumsAgree) within the tolerance of what they
//     show (Edges' outer pair A', B', which only measures the curve, need
//     only be on the object and visited: the error's bound, half the near
//     parents' spread, rests on A and B alone),
// and is summed where not. A parent outside the frame, on another object or
// not summed (the ground, an edge pixel's sub-samples) makes the pixel sum.
// What slips through is a feature of the sum narrower than the spacing whose
// parents agree on both sides of it.
#ifndef HAARCAST_CORE_SHARED_SMOOTH_H
#define HAARCAST_CORE_SHARED_SMOOTH_H

#include "haarcast/core/shared_language.h"

#ifdef __cplusplus
namespace haarcast::shared {
#endif

// The coarsest grid: every 8th pixel of every 8th row is summed.
HC_CONST uint kSmoothSumSpacing = 8u;
// Grid, then Edges and Centres at steps 4, 2 and 1.
HC_CONST uint kSmoothSumStages = 7u;
// RenderOptions::smoothSumTolerance's default (`render`, `serve`,
// `bench-frame`; RenderOptions keeps 0).
HC_CONST float kDefaultSmoothSumTolerance = 0.01f;
// A parent's mirror direction within this share of the lobe's median angle.
HC_CONST float kSmoothSumLobeShare = 0.5f;
// fused.comp's push constant `stage` where nothing is taken: one dispatch
// shades every sample.
HC_CONST uint kSmoothSumOff = 0xFFFFFFFFu;

HC_CONST uint kSmoothGrid = 0u;
HC_CONST uint kSmoothEdges = 1u;
HC_CONST uint kSmoothCentres = 2u;
// Stage s's kind and step: 0 the grid at the spacing; then Edges, Centres
// at spacing/2, …, 1.
HC_FUNCTION uint smoothStageKind(uint stage) { return stage == 0u ? kSmoothGrid : ((stage & 1u) != 0u ? kSmoothEdges : kSmoothCentres); }
HC_FUNCTION uint smoothStageStep(uint stage) { return stage == 0u ? kSmoothSumSpacing : (kSmoothSumSpacing >> ((stage + 1u) / 2u)); }

// A pixel's parents in a stage, as y·width + x.
struct SmoothParents {
  // 0: a Grid pixel (summed); 2: Edges, A and B at ±h across or down, then
  // A' and B' at ±3h beyond them where `outer` is 1; 4: Centres, the
  // midpoints left, right, above and below, then where `outer` is 1 the
  // pixels at ±3h beyond them (at4, at5 across; at6, at7 down: the stage
  // before visited them, as it did the midpoints); −1: a parent outside
  // the frame; −2: the pixel is not in this stage.
  int count;
  uint outer;
  uint at0, at1, at2, at3;
  uint at4, at5, at6, at7;
};

HC_FUNCTION SmoothParents smoothParents(uint stage, int x, int y, int width, int height) {
  SmoothParents p;
  p.count = -2;
  p.outer = 0u;
  p.at0 = 0u;
  p.at1 = 0u;
  p.at2 = 0u;
  p.at3 = 0u;
  p.at4 = 0u;
  p.at5 = 0u;
  p.at6 = 0u;
  p.at7 = 0u;
  const int h = int(smoothStageStep(stage));
  const uint kind = smoothStageKind(stage);
  if (kind == kSmoothGrid) {
    if (x % h == 0 && y % h == 0) p.count = 0;
    return p;
  }
  const int rx = x % (2 * h), ry = y % (2 * h);
  int dx = 0;
  int dy = 0;
  if (kind == kSmoothEdges) {
    if (rx == h && ry == 0) dx = 1;       // across
    else if (rx == 0 && ry == h) dy = 1;  // down
    else return p;
  } else {
    if (rx != h || ry != h) return p;
    if (x + h >= width || y + h >= height) {
      p.count = -1;
      return p;
    }
    p.count = 4;
    p.at0 = uint(y * width + x - h);
    p.at1 = uint(y * width + x + h);
    p.at2 = uint((y - h) * width + x);
    p.at3 = uint((y + h) * width + x);
    if (x - 3 * h >= 0 && y - 3 * h >= 0 && x + 3 * h < width && y + 3 * h < height) {
      p.outer = 1u;
      p.at4 = uint(y * width + x - 3 * h);
      p.at5 = uint(y * width + x + 3 * h);
      p.at6 = uint((y - 3 * h) * width + x);
      p.at7 = uint((y + 3 * h) * width + x);
    }
    return p;
  }
  // x − h·dx and y − h·dy are ≥ 0: x or y is ≥ h where its remainder is h.
  if (x + h * dx >= width || y + h * dy >= height) {
    p.count = -1;
    return p;
  }
  p.count = 2;
  p.at0 = uint((y - h * dy) * width + x - h * dx);
  p.at1 = uint((y + h * dy) * width + x + h * dx);
  if (x - 3 * h * dx >= 0 && y - 3 * h * dy >= 0 && x + 3 * h * dx < width && y + 3 * h * dy < height) {
    p.outer = 1u;
    p.at2 = uint((y - 3 * h * dy) * width + x - 3 * h * dx);
    p.at3 = uint((y + 3 * h * dy) * width + x + 3 * h * dx);
  }
  return p;
}

// The pixels of row y a stage visits: x = first, first + stride, … (what
// smoothParents says is the stage's, count ≠ −2); first −1 where none.
HC_FUNCTION int smoothRowFirst(uint stage, int y, HC_OUT(int) stride) {
  const int h = int(smoothStageStep(stage));
  const uint kind = smoothStageKind(stage);
  if (kind == kSmoothGrid) {
    stride = h;
    return y % h == 0 ? 0 : -1;
  }
  stride = 2 * h;
  const int ry = y % (2 * h);
  if (kind == kSmoothEdges) return ry == 0 ? h : (ry == h ? 0 : -1);
  return ry == h ? h : -1;
}

// The stage that visits pixel (x, y): the one whose smoothParents is not −2
// (every pixel has exactly one: SmoothSum.EveryPixelIsVisitedOnceAfterItsParents).
HC_FUNCTION uint smoothStageOf(int x, int y, int width, int height) {
  for (uint stage = 1u; stage < kSmoothSumStages; ++stage) {
    if (smoothParents(stage, x, y, width, height).count != -2) return stage;
  }
  return 0u;
}

// How many of a width × height frame's pixels stage `stage` visits: those
// with x ≡ rx (mod 2h) and y ≡ ry, for the stage's remainders (rx, ry) at
// its step h (the grid's: both ≡ 0 mod h).
HC_FUNCTION uint smoothCountOf(uint extent, uint remainder, uint modulus) {
  return extent > remainder ? (extent - remainder + modulus - 1u) / modulus : 0u;
}
HC_FUNCTION uint smoothStagePixels(uint stage, uint width, uint height) {
  const uint h = smoothStageStep(stage);
  const uint kind = smoothStageKind(stage);
  if (kind == kSmoothGrid) return smoothCountOf(width, 0u, h) * smoothCountOf(height, 0u, h);
  if (kind == kSmoothCentres) return smoothCountOf(width, h, 2u * h) * smoothCountOf(height, h, 2u * h);
  return smoothCountOf(width, h, 2u * h) * smoothCountOf(height, 0u, 2u * h) +
         smoothCountOf(width, 0u, 2u * h) * smoothCountOf(height, h, 2u * h);
}

// fused.comp's stage lists (push stage kSmoothSumList writes them, so that a
// stage's dispatches visit its own samples, not every covered sample): in
// words, stage k's count at k; its samples from smoothListOffset(k), which
// the host writes at kSmoothListOffsets + k once a frame: stages 1 and on
// first, each as long as it has pixels, then stage 0, which also takes
// every sample the smooth sum does not visit (as long as the covered
// samples can be). Each stage is two dispatches: the first
// (kSmoothPartDecide, an invocation a sample, its indirect dispatch (x, 1,
// 1) at kSmoothDecideArgs + 4k) shades the samples that take their
// parents' sum and lists the others, FusedPush::ownLists words further on,
// counted at kSmoothSumCounts + k; the second (kSmoothPartSum, a workgroup
// a sample, at kSmoothSumArgs + 4k) sums those.
HC_CONST uint kSmoothSumList = 0xFFFFFFFEu;
HC_CONST uint kSmoothPartDecide = 0u;
HC_CONST uint kSmoothPartSum = 1u;
HC_CONST uint kSmoothSumCounts = 8u;
HC_CONST uint kSmoothListOffsets = 16u;
HC_CONST uint kSmoothDecideArgs = 24u;
HC_CONST uint kSmoothSumArgs = kSmoothDecideArgs + 4u * kSmoothSumStages;
HC_CONST uint kSmoothListHeader = kSmoothSumArgs + 4u * kSmoothSumStages;
HC_FUNCTION uint smoothListOffset(uint stage, uint width, uint height) {
  uint offset = kSmoothListHeader;
  const uint end = stage == 0u ? kSmoothSumStages : stage;
  for (uint k = 1u; k < end; ++k) offset += smoothStagePixels(k, width, height);
  return offset;
}

// The mirror direction of the view in the object's frame: the slice frame's
// (0, cos θₒ, −sin θₒ) (the view is at φ = 0, shared_frame.h shadingFrame)
// turned by R = R_y(α) R_x(β) R_y(γ).
HC_FUNCTION vec3 smoothMirror(float alpha, float beta, float gamma, float thetaOut) {
  const float s = HC_SIN(thetaOut);
  const float c = HC_SIN(thetaOut + 1.57079632679f);
  return rotY(alpha) * (rotX(beta) * (rotY(gamma) * vec3(0.0f, c, -s)));
}

// Whether a parent's mirror direction is near enough the pixel's (both unit)
// for an object whose sharpest median lobe angle is `lobe`.
HC_FUNCTION bool smoothMirrorNear(vec3 pixel, vec3 parent, float cosLimit) { return dot(pixel, parent) >= cosLimit; }
HC_FUNCTION float smoothMirrorCos(float lobe) { return HC_SIN(1.57079632679f - min(kSmoothSumLobeShare * lobe, 3.14159265f)); }

// The brightness the tolerance is of: the dimmest of the near parents'
// brightest channels as shown (their radiance, point lights included), so
// that where the point lights are bright the sum may vary more, and next to
// a shadow's edge it may not.
HC_FUNCTION float smoothBrightness(SmoothParents p, vec3 shown0, vec3 shown1, vec3 shown2, vec3 shown3) {
  float dimmest = min(max(max(shown0.x, shown0.y), shown0.z), max(max(shown1.x, shown1.y), shown1.z));
  if (p.count == 4) {
    dimmest = min(dimmest, max(max(shown2.x, shown2.y), shown2.z));
    dimmest = min(dimmest, max(max(shown3.x, shown3.y), shown3.z));
  }
  return dimmest;
}

// Whether a line of four parents 2h apart, A' A B B' with the pixel midway
// between A and B, may give the pixel A and B's mean, against ε:
// - the curve through them: |A' − A − B + B'|/16, the cubic at the middle
//   less the line (the line's error, h²f''/2, for a quadratic), at most ε;
// - a step between A and B, which the curve cannot see, by their third
//   difference |A' − 3A + 3B − B'|/2: zero on a quadratic and S for a step
//   S between A and B (A' = A, B = B'), at most kSmoothStepLimit·ε, so
//   that the mean errs by at most 0.75ε there;
// - their spread |B − A|, a slope, at most kSmoothSlopeLimit·ε: a guard (a
//   line's midpoint is exact, and the bend measures the rest).
HC_CONST float kSmoothStepLimit = 1.5f;
HC_CONST float kSmoothSlopeLimit = 16.0f;
HC_FUNCTION float smoothLargest(vec3 v) { return max(max(v.x, v.y), v.z); }
HC_FUNCTION bool smoothLineAgrees(vec3 outerA, vec3 a, vec3 b, vec3 outerB, float epsilon) {
  if (!(smoothLargest(0.5f * abs(outerA - 3.0f * a + 3.0f * b - outerB)) <= kSmoothStepLimit * epsilon)) return false;
  if (!(smoothLargest(abs(b - a)) <= kSmoothSlopeLimit * epsilon)) return false;
  return smoothLargest(abs(outerA - a - b + outerB)) / 16.0f <= epsilon;
}

// Whether the parents' sums may stand for the pixel's, measured against
// ε = tolerance × brightness in each channel (s0 … s3 at at0 … at3, s4 …
// s7 at at4 … at7):
// - Edges with outer: their line agrees (smoothLineAgrees);
// - Centres: the across and the down means within 2ε of each other (a
//   saddle, which neither line shows), and with outer each line agrees,
//   across (at4, at0, at1, at5) and down (at6, at2, at3, at7); without,
//   the four's spread, max − min, at most 4ε (a step errs by half of it);
// - Edges without outer: A and B within ε.
HC_FUNCTION bool smoothSumsAgree(SmoothParents p, vec3 s0, vec3 s1, vec3 s2, vec3 s3, vec3 s4, vec3 s5, vec3 s6, vec3 s7,
                                 float brightness, float tolerance) {
  const float epsilon = tolerance * brightness;
  if (p.count == 2) return p.outer != 0u ? smoothLineAgrees(s2, s0, s1, s3, epsilon) : smoothLargest(abs(s1 - s0)) <= epsilon;
  if (!(smoothLargest(0.25f * abs(s0 + s1 - s2 - s3)) <= epsilon)) return false;
  if (p.outer != 0u) return smoothLineAgrees(s4, s0, s1, s5, epsilon) && smoothLineAgrees(s6, s2, s3, s7, epsilon);
  const vec3 spread = max(max(s0, s1), max(s2, s3)) - min(min(s0, s1), min(s2, s3));
  return smoothLargest(spread) <= 4.0f * epsilon;
}

// The sum the pixel takes: the mean of A and B, or of the four midpoints.
HC_FUNCTION vec3 smoothParentsSum(SmoothParents p, vec3 s0, vec3 s1, vec3 s2, vec3 s3) {
  return p.count == 4 ? (s0 + s1 + s2 + s3) / 4.0f : (s0 + s1) / 2.0f;
}

#ifdef __cplusplus
}  // namespace haarcast::shared
#endif

#endif  // HAARCAST_CORE_SHARED_SMOOTH_H
