// `fused`'s sum taken from a pixel's neighbours where they show it is smooth
// (RenderOptions::smoothSumTolerance; docs/design.md, "Where the sum is
// smooth across the image").
//
// The pass's sum (core/fused.h FusedSum: the light's rest × V × ρ) changes
// slowly across a surface wherever the lobe is wider than a pixel's turn and
// V has no edge; what a pixel shows sharply — the point lights and their
// shadows, the sky other objects hide, the lobe path's mirror core — is not
// in it and stays each pixel's own. So the frame's pixels are visited coarse
// to fine, in the order of adaptive image subdivision: every pixel of a grid
// `spacing` apart is summed; then, halving the step, each midpoint of the
// grid's edges (two parents, across or down) and each centre of its squares
// (four parents, the midpoints just done) takes its parents' mean sum where
// their spread is within the tolerance of what the pixel shows, and is
// summed where it is not. A parent outside the frame, on another object or
// not summed (the ground, an edge pixel's sub-samples) makes the pixel sum.
// What slips through is a feature of the sum narrower than the spacing whose
// parents agree on both sides of it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace haarcast::render {

// The coarsest grid: every 4th pixel of every 4th row is summed (1/16 of
// a frame's pixels at least).
inline constexpr int kSmoothSumSpacing = 4;
// What `render`, `serve` and `bench-frame` take (RenderOptions keeps 0).
inline constexpr float kDefaultSmoothSumTolerance = 0.01f;

struct SmoothSumStage {
  enum class Kind { Grid, Edges, Centres };
  Kind kind = Kind::Grid;
  int step = 0;  // the grid's spacing (Grid), or the distance to the parents
};

// Grid at `spacing`, then Edges and Centres at spacing/2, …, 1. `spacing` a
// power of two ≥ 1 (checked: std::invalid_argument).
std::vector<SmoothSumStage> smoothSumStages(int spacing);

// A pixel's parents in a stage, as y·width + x.
struct SmoothSumParents {
  // 0: a Grid pixel (summed); 2: Edges, A and B at ±h across or down, then
  // A' and B' at ±3h beyond them where `outer`; 4: Centres, the midpoints
  // left, right, above and below; -1: a parent outside the frame; -2: the
  // pixel is not in this stage.
  int count = 0;
  std::array<std::uint32_t, 4> at{};
  bool outer = false;
};
SmoothSumParents smoothSumParents(const SmoothSumStage& stage, int x, int y, int width, int height);

// Whether a pixel's sum may come from its parents at all, before their sums
// are compared: the sum is the light's rest blurred by the lobe, so it is
// smooth over the image only where the pixels' mirror directions (the
// camera ray reflected about the normal, unit vectors) move by less than
// the lobe is wide. Each parent's is within kSmoothSumLobeShare × `lobe`
// (the object's sharpest median lobe angle) of the pixel's. A near-mirror's
// sum, sampled by the map's directions, changes from pixel to pixel more
// than its neighbours' agreement can show.
inline constexpr float kSmoothSumLobeShare = 0.5f;
bool mirrorsWithinLobe(const glm::vec3& pixel, std::span<const glm::vec3> parents, float lobe);

// The sum a pixel takes from its parents' (`sums` in the order of `at`):
// the mean of A and B, or of the four midpoints.
std::array<float, 3> parentsSum(const SmoothSumParents& parents, std::span<const std::array<float, 3>> sums);

// Whether that sum may stand for the pixel, before the pixel is shaded (so
// each pixel is shaded once): measured against ε = `tolerance` ×
// `brightness`, the dimmest of the near parents' brightest channels as
// shown (their radiance, point lights included), so that where the point
// lights are bright the sum may vary more, and next to a shadow's edge it
// may not; in each channel,
// - how far the mean is from a curve through the parents: Edges with
//   outer, |A' − A − B + B'|/16 (the cubic through the four at the middle,
//   less the line, exact for a quadratic); Centres, the across and the
//   down means' difference, halved; each at most ε;
// - and the parents' spread, max − min, at most 4ε (only ε for Edges
//   without outer): a step between two parents the curve cannot see
//   errs by half of it at most.
bool sumsAgree(const SmoothSumParents& parents, std::span<const std::array<float, 3>> sums, float brightness,
               float tolerance);
// That brightness, from the near parents' radiance as shown.
float parentsBrightness(const SmoothSumParents& parents, std::span<const std::array<float, 3>> shown);

}  // namespace haarcast::render
