// fused's sum taken from a pixel's neighbours (smooth_sum.h): the order the
// pixels are visited in, the agreement rule, and the CPU backend's frames.
#include "haarcast/render/smooth_sum.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"

namespace haarcast::render {
namespace {

using Sums = std::vector<std::array<float, 3>>;

// Every pixel is visited once, and every parent before its child.
TEST(SmoothSum, EveryPixelIsVisitedOnceAfterItsParents) {
  for (const auto [w, h] : {std::pair{13, 9}, {16, 16}, {1, 1}, {5, 1}, {1, 7}, {33, 20}}) {
    std::vector<int> visited(static_cast<std::size_t>(w * h), -1);
    const std::vector<SmoothSumStage> stages = smoothSumStages(kSmoothSumSpacing);
    for (std::size_t k = 0; k < stages.size(); ++k) {
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const SmoothSumParents p = smoothSumParents(stages[k], x, y, w, h);
          if (p.count == -2) continue;
          const std::size_t i = static_cast<std::size_t>(y * w + x);
          EXPECT_EQ(visited[i], -1) << w << "×" << h << " (" << x << ", " << y << ") twice";
          visited[i] = static_cast<int>(k);
          const int n = p.count == 2 && p.outer ? 4 : std::max(p.count, 0);
          for (int j = 0; j < n; ++j) {
            const int parent = visited[p.at[static_cast<std::size_t>(j)]];
            EXPECT_TRUE(parent >= 0 && parent < static_cast<int>(k)) << "(" << x << ", " << y << ") before a parent";
          }
        }
      }
    }
    EXPECT_EQ(std::count(visited.begin(), visited.end(), -1), 0) << w << "×" << h << ": a pixel never visited";
  }
  EXPECT_THROW(smoothSumStages(3), std::invalid_argument);
}

TEST(SmoothSum, ParentsAreTheGridNeighboursAtTheStagesStep) {
  const std::vector<SmoothSumStage> stages = smoothSumStages(4);
  ASSERT_EQ(stages.size(), 5u);  // grid 4, edges 2, centres 2, edges 1, centres 1
  const int w = 20, h = 20;
  auto at = [&](int x, int y) { return static_cast<std::uint32_t>(y * w + x); };
  SmoothSumParents p = smoothSumParents(stages[1], 10, 8, w, h);  // across, step 2
  ASSERT_EQ(p.count, 2);
  EXPECT_EQ(p.at[0], at(8, 8));
  EXPECT_EQ(p.at[1], at(12, 8));
  ASSERT_TRUE(p.outer);
  EXPECT_EQ(p.at[2], at(4, 8));
  EXPECT_EQ(p.at[3], at(16, 8));
  p = smoothSumParents(stages[1], 4, 2, w, h);  // down, step 2: no row -4
  ASSERT_EQ(p.count, 2);
  EXPECT_EQ(p.at[0], at(4, 0));
  EXPECT_EQ(p.at[1], at(4, 4));
  EXPECT_FALSE(p.outer);
  p = smoothSumParents(stages[4], 5, 7, w, h);  // a square's centre, step 1
  ASSERT_EQ(p.count, 4);
  EXPECT_EQ(p.at[0], at(4, 7));
  EXPECT_EQ(p.at[3], at(5, 8));
  EXPECT_EQ(smoothSumParents(stages[1], 18, 0, w, h).count, -1);  // x + 2 = 20 is outside
}

// ε = 0.01 of parents that show 100: 1.
TEST(SmoothSum, ALineIsTakenAndABumpOrAStepIsNot) {
  const float shown = 100.0f;  // the parents' dimmest brightest channel
  const float tolerance = 0.01f;
  auto edges = [](float a, float b, float outerA, float outerB) {
    return Sums{{a, a, a}, {b, b, b}, {outerA, outerA, outerA}, {outerB, outerB, outerB}};
  };
  SmoothSumParents across;
  across.count = 2;
  across.outer = true;
  // A line, whatever its slope within the step limit 4ε.
  EXPECT_TRUE(sumsAgree(across, edges(10, 13, 7, 16), shown, tolerance));
  EXPECT_EQ(parentsSum(across, edges(10, 13, 7, 16))[0], 11.5f);
  // A bump: |A' − A − B + B'|/16 = 20/16 > 1.
  EXPECT_FALSE(sumsAgree(across, edges(10, 10, 0, 0), shown, tolerance));
  EXPECT_TRUE(sumsAgree(across, edges(10, 10, 2, 2), shown, tolerance));  // 16/16
  // A step the outer pair cannot see: its size alone, at most 4ε.
  EXPECT_FALSE(sumsAgree(across, edges(10, 15, 10, 15), shown, tolerance));
  // Without the outer pair, the spread at most ε.
  SmoothSumParents near = across;
  near.outer = false;
  EXPECT_FALSE(sumsAgree(near, edges(10, 12, 0, 0), shown, tolerance));
  EXPECT_TRUE(sumsAgree(near, edges(10, 11, 0, 0), shown, tolerance));
  // One channel is enough to refuse.
  Sums red = edges(10, 11, 0, 0);
  red[1][2] = 13.0f;
  EXPECT_FALSE(sumsAgree(near, red, shown, tolerance));
  // The square's centre: the across and the down means agree within 2ε.
  SmoothSumParents centre;
  centre.count = 4;
  EXPECT_TRUE(sumsAgree(centre, Sums{{10, 10, 10}, {10, 10, 10}, {12, 12, 12}, {12, 12, 12}}, shown, tolerance));
  EXPECT_FALSE(sumsAgree(centre, Sums{{10, 10, 10}, {10, 10, 10}, {13, 13, 13}, {13, 13, 13}}, shown, tolerance));
  EXPECT_EQ(parentsSum(centre, Sums{{10, 0, 0}, {11, 0, 0}, {12, 0, 0}, {13, 0, 0}})[0], 11.5f);
  // Brighter point lights shown allow more: the tolerance is of what the parents show.
  EXPECT_TRUE(sumsAgree(near, edges(10, 12, 0, 0), 200.0f, tolerance));
  // …and the dimmest parent sets it: next to a shadow's edge, less.
  EXPECT_EQ(parentsBrightness(near, Sums{{200, 50, 0}, {0, 90, 80}}), 90.0f);
  EXPECT_EQ(parentsBrightness(centre, Sums{{200, 0, 0}, {150, 0, 0}, {300, 0, 0}, {0, 0, 40}}), 40.0f);
}

TEST(SmoothSum, AParentsMirrorDirectionMustBeWithinHalfTheLobe) {
  const float lobe = 0.2f;  // radians: parents within 0.1 of the pixel's direction
  const glm::vec3 pixel(0.0f, 0.0f, 1.0f);
  auto turned = [](float angle) { return glm::vec3(std::sin(angle), 0.0f, std::cos(angle)); };
  const std::vector<glm::vec3> near{turned(0.09f), turned(-0.05f)};
  const std::vector<glm::vec3> far{turned(0.09f), turned(-0.11f)};
  EXPECT_TRUE(mirrorsWithinLobe(pixel, near, lobe));
  EXPECT_FALSE(mirrorsWithinLobe(pixel, far, lobe));
  EXPECT_TRUE(mirrorsWithinLobe(pixel, far, 0.25f));
}

RenderOptions smallFused() {
  RenderOptions o;
  o.level = 5;
  o.thetaSamples = 4;
  o.sliceSupersampling = 2;
  o.visibility.supersampling = 1;
  o.sumTolerance = 0.1f;
  return o;
}

FrameRequest requestFor(const Scene& scene) {
  FrameRequest request;
  request.width = 192;
  request.height = 144;
  request.camera = scene.camera;
  return request;
}

// The built-in scene with a Lambert sphere and a ggx:0.3 torus (the sky's
// sun a point light: sharp terminators and shadows) at a small size: with a
// smooth-sum tolerance a quarter of their samples or more (a third when
// measured) take their sum from their neighbours, every other one is the
// full frame's to the bit, and each pixel stays within what the rule allows
// of the full frame.
TEST(CpuBackend, ASmoothSumTakesAQuarterOfThePixelsAndEachStaysNearTheFullSum) {
  Scene scene = defaultScene();
  scene.objects[0].material = materialFromSpec("lambert");
  const RenderOptions o = smallFused();
  const FrameRequest request = requestFor(scene);
  const Frame full = makeCpuRenderer(scene, o)->render(request);
  RenderOptions smooth = o;
  const float tolerance = 0.01f;
  smooth.smoothSumTolerance = tolerance;
  const Frame taken = makeCpuRenderer(scene, smooth)->render(request);
  EXPECT_EQ(full.smoothSamples, 0u);
  EXPECT_EQ(taken.passSamples, full.passSamples);
  EXPECT_GT(taken.smoothSamples, taken.passSamples / 4) << "of " << taken.passSamples;
  EXPECT_LT(taken.passDirections, full.passDirections * 9 / 10);
  std::size_t differ = 0;
  double worst = 0.0;
  for (int y = 0; y < full.image.height; ++y) {
    for (int x = 0; x < full.image.width; ++x) {
      float brightest = 0.0f, most = 0.0f;
      for (int c = 0; c < 3; ++c) {
        brightest = std::max(brightest, full.image.at(y, x, c));
        most = std::max(most, std::abs(taken.image.at(y, x, c) - full.image.at(y, x, c)));
      }
      if (most > 0.0f) ++differ;
      if (brightest > 0.0f) worst = std::max(worst, static_cast<double>(most / brightest));
    }
  }
  EXPECT_LE(differ, taken.smoothSamples) << "a pixel summed in full differs from the full frame's";
  // A step between two parents errs by half of 4ε at most; the curve's
  // estimate is no bound, so twice that is allowed.
  EXPECT_LE(worst, 4.0 * tolerance);
}

// A near-mirror's sum, sampled by the map's directions, is not smooth from
// pixel to pixel whatever its neighbours say: its mirror directions move
// by more than half its lobe between any two, and it takes none.
TEST(CpuBackend, ANearMirrorTakesNoSumFromItsNeighbours) {
  Scene scene = defaultScene();
  scene.objects[0].material = materialFromSpec("ggx:0.02");
  scene.objects.erase(scene.objects.begin() + 1);  // the torus
  RenderOptions o = smallFused();
  o.smoothSumTolerance = 0.02f;
  const Frame frame = makeCpuRenderer(scene, o)->render(requestFor(scene));
  EXPECT_GT(frame.passSamples, 1000u);
  EXPECT_EQ(frame.smoothSamples, 0u);
}

}  // namespace
}  // namespace haarcast::render
