// fused's sum taken from a pixel's neighbours (core/shared_smooth.h): the order the
// pixels are visited in, the agreement rule, and the CPU backend's frames.
#include "haarcast/core/shared_frame.h"
#include "haarcast/core/shared_smooth.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"

namespace haarcast::render {
namespace {

using shared::SmoothParents;

// Every pixel is visited once, and every parent before its child.
TEST(SmoothSum, EveryPixelIsVisitedOnceAfterItsParents) {
  for (const auto& [w, h] : {std::pair{13, 9}, {16, 16}, {1, 1}, {5, 1}, {1, 7}, {33, 20}}) {
    std::vector<int> visited(static_cast<std::size_t>(w * h), -1);
    for (shared::uint k = 0; k < shared::kSmoothSumStages; ++k) {
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          const SmoothParents p = shared::smoothParents(k, x, y, w, h);
          if (p.count == -2) continue;
          const std::size_t i = static_cast<std::size_t>(y * w + x);
          EXPECT_EQ(visited[i], -1) << w << "×" << h << " (" << x << ", " << y << ") twice";
          visited[i] = static_cast<int>(k);
          const std::array<shared::uint, 8> at{p.at0, p.at1, p.at2, p.at3, p.at4, p.at5, p.at6, p.at7};
          const int n = p.outer != 0u ? 2 * p.count : std::max(p.count, 0);
          for (int j = 0; j < n; ++j) {
            ASSERT_LT(at[static_cast<std::size_t>(j)], static_cast<shared::uint>(w * h));
            const int parent = visited[at[static_cast<std::size_t>(j)]];
            EXPECT_TRUE(parent >= 0 && parent < static_cast<int>(k)) << "(" << x << ", " << y << ") before a parent";
          }
        }
      }
    }
    EXPECT_EQ(std::count(visited.begin(), visited.end(), -1), 0) << w << "×" << h << ": a pixel never visited";
    // smoothRowFirst lists each row's pixels of a stage, no more, no fewer.
    for (shared::uint k = 0; k < shared::kSmoothSumStages; ++k) {
      for (int y = 0; y < h; ++y) {
        int stride = 0;
        const int first = shared::smoothRowFirst(k, y, stride);
        std::vector<int> listed, inStage;
        for (int x = first; first >= 0 && x < w; x += stride) listed.push_back(x);
        for (int x = 0; x < w; ++x)
          if (shared::smoothParents(k, x, y, w, h).count != -2) inStage.push_back(x);
        EXPECT_EQ(listed, inStage) << "stage " << k << ", row " << y << " of " << w << "×" << h;
      }
    }
  }
}

// fused.comp's stage lists: a pixel's stage is the one that visits it, a
// stage's list is as long as its pixels, and the lists lie one after
// another (stage 0 last, open-ended: it also takes the samples not visited).
TEST(SmoothSum, EachStagesListHoldsItsPixelsAndNoOtherStages) {
  for (const auto& [w, h] : {std::pair{13, 9}, {16, 16}, {1, 1}, {5, 1}, {1, 7}, {33, 20}, {1280, 720}, {97, 1}}) {
    const auto uw = static_cast<shared::uint>(w), uh = static_cast<shared::uint>(h);
    std::array<shared::uint, shared::kSmoothSumStages> pixels{};
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const shared::uint k = shared::smoothStageOf(x, y, w, h);
        ASSERT_LT(k, shared::kSmoothSumStages);
        EXPECT_NE(shared::smoothParents(k, x, y, w, h).count, -2) << "(" << x << ", " << y << ") of " << w << "×" << h;
        ++pixels[k];
      }
    }
    shared::uint offset = shared::kSmoothListHeader;
    for (shared::uint k = 1; k < shared::kSmoothSumStages; ++k) {
      EXPECT_EQ(shared::smoothStagePixels(k, uw, uh), pixels[k]) << "stage " << k << " of " << w << "×" << h;
      EXPECT_EQ(shared::smoothListOffset(k, uw, uh), offset) << "stage " << k << " of " << w << "×" << h;
      offset += pixels[k];
    }
    EXPECT_EQ(shared::smoothStagePixels(0, uw, uh), pixels[0]);
    EXPECT_EQ(shared::smoothListOffset(0, uw, uh), offset) << w << "×" << h << ": stage 0 after the others";
  }
  // The header: a count per stage, of its samples and of those that sum
  // their own, where each stage's list starts, then each stage's two
  // dispatches (x, y, z, pad), apart.
  EXPECT_GE(shared::kSmoothSumCounts, shared::kSmoothSumStages);
  EXPECT_GE(shared::kSmoothListOffsets, shared::kSmoothSumCounts + shared::kSmoothSumStages);
  EXPECT_GE(shared::kSmoothDecideArgs, shared::kSmoothListOffsets + shared::kSmoothSumStages);
  EXPECT_EQ(shared::kSmoothSumArgs, shared::kSmoothDecideArgs + 4 * shared::kSmoothSumStages);
  EXPECT_EQ(shared::kSmoothListHeader, shared::kSmoothSumArgs + 4 * shared::kSmoothSumStages);
}

TEST(SmoothSum, ParentsAreTheGridNeighboursAtTheStagesStep) {
  ASSERT_EQ(shared::kSmoothSumSpacing, 8u);
  // grid 8, edges 4, centres 4, edges 2, centres 2, edges 1, centres 1
  ASSERT_EQ(shared::kSmoothSumStages, 7u);
  EXPECT_EQ(shared::smoothStageStep(0), 8u);
  EXPECT_EQ(shared::smoothStageKind(0), shared::kSmoothGrid);
  for (shared::uint k = 1; k < shared::kSmoothSumStages; ++k) {
    EXPECT_EQ(shared::smoothStageStep(k), 8u >> ((k + 1) / 2)) << k;
    EXPECT_EQ(shared::smoothStageKind(k), k % 2 == 1 ? shared::kSmoothEdges : shared::kSmoothCentres) << k;
  }
  const int w = 20, h = 20;
  auto at = [&](int x, int y) { return static_cast<shared::uint>(y * w + x); };
  SmoothParents p = shared::smoothParents(3, 10, 8, w, h);  // across, step 2
  ASSERT_EQ(p.count, 2);
  EXPECT_EQ(p.at0, at(8, 8));
  EXPECT_EQ(p.at1, at(12, 8));
  ASSERT_EQ(p.outer, 1u);
  EXPECT_EQ(p.at2, at(4, 8));
  EXPECT_EQ(p.at3, at(16, 8));
  p = shared::smoothParents(3, 4, 2, w, h);  // down, step 2: no row -4
  ASSERT_EQ(p.count, 2);
  EXPECT_EQ(p.at0, at(4, 0));
  EXPECT_EQ(p.at1, at(4, 4));
  EXPECT_EQ(p.outer, 0u);
  p = shared::smoothParents(6, 5, 7, w, h);  // a square's centre, step 1
  ASSERT_EQ(p.count, 4);
  EXPECT_EQ(p.at0, at(4, 7));
  EXPECT_EQ(p.at3, at(5, 8));
  ASSERT_EQ(p.outer, 1u);  // ±3 across and down, each visited by stage 3 as the midpoints were
  EXPECT_EQ(p.at4, at(2, 7));
  EXPECT_EQ(p.at5, at(8, 7));
  EXPECT_EQ(p.at6, at(5, 4));
  EXPECT_EQ(p.at7, at(5, 10));
  for (const shared::uint q : {p.at4, p.at5, p.at6, p.at7})
    EXPECT_EQ(shared::smoothParents(5, static_cast<int>(q % w), static_cast<int>(q / w), w, h).count, 2) << q;
  EXPECT_EQ(shared::smoothParents(6, 1, 7, w, h).outer, 0u);  // no column −2
  EXPECT_EQ(shared::smoothParents(3, 18, 0, w, h).count, -1);  // x + 2 = 20 is outside
  p = shared::smoothParents(1, 12, 0, w, h);  // across, step 4
  ASSERT_EQ(p.count, 2);
  EXPECT_EQ(p.at0, at(8, 0));
  EXPECT_EQ(p.at1, at(16, 0));
  EXPECT_EQ(p.outer, 0u);  // no column −12
}

glm::vec3 grey(float v) { return glm::vec3(v); }

// ε = 0.01 of parents that show 100: 1.
TEST(SmoothSum, ALineIsTakenAndABumpOrAStepIsNot) {
  const float shown = 100.0f;  // the parents' dimmest brightest channel
  const float tolerance = 0.01f;
  SmoothParents across{2, 1u, 0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u};
  // s0 … s7 as smoothSumsAgree takes them (the missing ones black).
  auto agreeRgb = [&](const SmoothParents& p, std::vector<glm::vec3> s) {
    s.resize(8, grey(0));
    return shared::smoothSumsAgree(p, s[0], s[1], s[2], s[3], s[4], s[5], s[6], s[7], shown, tolerance);
  };
  auto agree = [&](const SmoothParents& p, float a, float b, float outerA, float outerB, float brightness = 100.0f) {
    return shared::smoothSumsAgree(p, grey(a), grey(b), grey(outerA), grey(outerB), grey(0), grey(0), grey(0), grey(0),
                                   brightness, tolerance);
  };
  // A line, whatever its slope within the slope guard 16ε.
  EXPECT_TRUE(agree(across, 10, 13, 7, 16));
  EXPECT_EQ(shared::smoothParentsSum(across, grey(10), grey(13), grey(7), grey(16)).x, 11.5f);
  EXPECT_TRUE(agree(across, 10, 26, -6, 42));
  EXPECT_FALSE(agree(across, 10, 27, -7, 44));
  // A bump: |A' − A − B + B'|/16 = 20/16 > 1.
  EXPECT_FALSE(agree(across, 10, 10, 0, 0));
  EXPECT_TRUE(agree(across, 10, 10, 2, 2));  // 16/16
  // A step between A and B, which the curve does not see: its third
  // difference |A' − 3A + 3B − B'|/2 is its size, at most 1.5ε.
  EXPECT_FALSE(agree(across, 10, 15, 10, 15));
  EXPECT_FALSE(agree(across, 10, 12, 10, 12));
  EXPECT_TRUE(agree(across, 10, 11.4f, 10, 11.4f));
  // On a quadratic the third difference is zero: only the bend decides.
  EXPECT_TRUE(agree(across, 8, 12, 12, 24));  // 9 + 2x + x² at x = ∓1, ∓3: bend 16/16
  // Without the outer pair, the spread at most ε.
  SmoothParents near = across;
  near.outer = 0u;
  EXPECT_FALSE(agree(near, 10, 12, 0, 0));
  EXPECT_TRUE(agree(near, 10, 11, 0, 0));
  // One channel is enough to refuse.
  EXPECT_FALSE(agreeRgb(near, {grey(10), glm::vec3(11, 11, 13), grey(0), grey(0)}));
  // The square's centre: the across and the down means agree within 2ε,
  // and without outer parents the four's spread is at most 4ε.
  const SmoothParents centre{4, 0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u, 0u};
  EXPECT_TRUE(agreeRgb(centre, {grey(10), grey(10), grey(12), grey(12)}));
  EXPECT_FALSE(agreeRgb(centre, {grey(10), grey(10), grey(13), grey(13)}));
  EXPECT_FALSE(agreeRgb(centre, {grey(10), grey(18), grey(10), grey(18)}));  // a slope of 8ε: spread 8
  // With outer parents (at ±3h across, then down) each line is judged as
  // an edge's: the same slope is taken …
  SmoothParents wide = centre;
  wide.outer = 1u;
  EXPECT_TRUE(agreeRgb(wide, {grey(10), grey(18), grey(10), grey(18), grey(2), grey(26), grey(2), grey(26)}));
  // … a step across between the near pair is not (third difference 8ε),
  EXPECT_FALSE(agreeRgb(wide, {grey(10), grey(18), grey(14), grey(14), grey(10), grey(18), grey(14), grey(14)}));
  // nor a bend down of more than ε (|A' − A − B + B'|/16 = 32/16),
  EXPECT_FALSE(agreeRgb(wide, {grey(14), grey(14), grey(14), grey(14), grey(14), grey(14), grey(30), grey(30)}));
  // nor a saddle neither line shows: the across and the down means 4ε apart.
  EXPECT_FALSE(agreeRgb(wide, {grey(12), grey(12), grey(8), grey(8), grey(12), grey(12), grey(8), grey(8)}));
  EXPECT_EQ(shared::smoothParentsSum(centre, grey(10), grey(11), grey(12), grey(13)).x, 11.5f);
  // Brighter point lights shown allow more: the tolerance is of what the parents show…
  EXPECT_TRUE(agree(near, 10, 12, 0, 0, 200.0f));
  // …and the dimmest parent sets it: next to a shadow's edge, less.
  EXPECT_EQ(shared::smoothBrightness(near, glm::vec3(200, 50, 0), glm::vec3(0, 90, 80), grey(0), grey(0)), 90.0f);
  EXPECT_EQ(shared::smoothBrightness(centre, glm::vec3(200, 0, 0), glm::vec3(150, 0, 0), glm::vec3(300, 0, 0),
                                     glm::vec3(0, 0, 40)), 40.0f);
}

TEST(SmoothSum, AParentsMirrorDirectionMustBeWithinHalfTheLobe) {
  const float cosLimit = shared::smoothMirrorCos(0.2f);  // radians: parents within 0.1 of the pixel's direction
  EXPECT_NEAR(cosLimit, std::cos(0.1f), 1e-6f);
  const glm::vec3 pixel(0.0f, 0.0f, 1.0f);
  auto turned = [](float angle) { return glm::vec3(std::sin(angle), 0.0f, std::cos(angle)); };
  EXPECT_TRUE(shared::smoothMirrorNear(pixel, turned(0.09f), cosLimit));
  EXPECT_TRUE(shared::smoothMirrorNear(pixel, turned(-0.05f), cosLimit));
  EXPECT_FALSE(shared::smoothMirrorNear(pixel, turned(-0.11f), cosLimit));
}

// The mirror direction from the Euler angles and θₒ is the view reflected
// about the normal: with the frame of shadingFrame, R·(0, cos θₒ, −sin θₒ)
// = 2(n·wo)n − wo.
TEST(SmoothSum, TheMirrorIsTheViewReflectedAboutTheNormal) {
  const glm::vec3 n = glm::normalize(glm::vec3(0.3f, 0.8f, -0.2f));
  const glm::vec3 wo = glm::normalize(glm::vec3(-0.5f, 0.4f, 0.7f));
  float thetaOut = 0.0f;
  const glm::mat3 frame = shared::shadingFrame(n, wo, thetaOut);
  const glm::vec3 e = shared::eulerYXYOf(frame);
  const glm::vec3 mirror = shared::smoothMirror(e.x, e.y, e.z, thetaOut);
  const glm::vec3 expected = 2.0f * glm::dot(n, wo) * n - wo;
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mirror[c], expected[c], 1e-5f);
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
  // The fused stage's parts (Frame::parts), in order, add up to it.
  std::vector<std::string> names;
  double parts = 0.0, stage = -1.0;
  for (const StageTime& p : taken.parts) {
    names.push_back(p.name);
    EXPECT_GE(p.seconds, 0.0) << p.name;
    parts += p.seconds;
  }
  for (const StageTime& st : taken.stages)
    if (st.name == "fused") stage = st.seconds;
  EXPECT_EQ(names, (std::vector<std::string>{"fused: ground sky grid", "fused: points and rays", "fused: sums from neighbours",
                                             "fused: rest"}));
  EXPECT_NEAR(parts, stage, 1e-3 * stage + 1e-5);
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
