// A map level per object (render/object_levels.h, core/lobe.h chooseLevel):
// which level each object gets, the flags' level choices, and that a frame
// with objects at several levels draws each object exactly as a frame at
// that object's level alone would.
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/object_levels.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdio>
#include <string>
#include <stdexcept>
#include <vector>

#include "haarcast/core/lobe.h"
#include "haarcast/render/renderer.h"

namespace haarcast::render {
namespace {

// The default scene without its ground, its sphere Lambert (level 5 under
// automatic levels) beside its ggx:0.3 torus (6): the sphere fills the
// left half of the frame, the torus the right.
Scene twoObjects() {
  Scene s = defaultScene();
  std::erase_if(s.objects, [](const SceneObject& o) { return o.ground; });
  s.objects[0].material = materialFromSpec("lambert");
  return s;
}

RenderOptions options(int level, bool automatic) {
  RenderOptions o;
  o.width = o.height = 40;
  o.level = level;
  o.automaticLevel = automatic;
  o.thetaSamples = 8;
  o.sliceSupersampling = 2;
  o.visibility.supersampling = 1;
  o.refine.rounds = 0;
  return o;
}

std::vector<int> levelsOf(const std::vector<ObjectPlan>& levels) {
  std::vector<int> out;
  for (const ObjectPlan& l : levels) out.push_back(l.level);
  return out;
}

// The level and what a pixel may spend there are one plan per object, from
// one measure of its material: the ground is closed form, an object below
// the cells' level sums every direction, and the neighbours' mirror
// directions may turn by half the lobe chooseLevel spans.
TEST(ObjectLevels, ThePlanIsTheLevelTheCellsAndTheNeighboursFromOneMeasure) {
  Scene scene = defaultScene();  // phong:64 sphere, ggx:0.3 torus, ground
  RenderOptions o = options(6, true);
  o.sumTolerance = 0.1f;
  o.smoothSumTolerance = 0.01f;
  const std::vector<ObjectPlan> plans = planObjects(scene, o);
  ASSERT_EQ(plans.size(), 3u);
  const ObjectPlan& sphere = plans[0];
  EXPECT_EQ(sphere.level, 6);
  EXPECT_EQ(sphere.sumTolerance, 0.1f);
  EXPECT_EQ(sphere.smoothSumTolerance, 0.01f);
  EXPECT_EQ(sphere.sharpestLobe, static_cast<float>(sharpestMedian(sphere.lobes)));
  EXPECT_LT(sphere.sharpestLobe, plans[1].sharpestLobe) << "phong:64 is sharper than ggx:0.3";
  const ObjectPlan& ground = plans[2];
  EXPECT_EQ(ground.sumTolerance, 0.0f);
  EXPECT_EQ(ground.smoothSumTolerance, 0.0f);
  EXPECT_EQ(describePlan(ground, true, RotationMethod::Fused), "closed form");
  char within[32];
  std::snprintf(within, sizeof within, "%.1f°", static_cast<double>(sphere.sharpestLobe) * 90.0 / kPi);
  EXPECT_EQ(describePlan(sphere, false, RotationMethod::Fused),
            std::string("level 6, cells τ 0.1, a neighbour's sum within ") + within);
  // Below the cells' level every direction is summed.
  const std::vector<ObjectPlan> coarse = planObjects(scene, options(4, false));
  EXPECT_EQ(coarse[0].sumTolerance, 0.0f);
  EXPECT_EQ(describePlan(coarse[0], false, RotationMethod::Fused), "level 4, every direction");
  // The prepared objects carry the plan, as the log and the renderers say it.
  const PreparedScene prepared = prepareScene(scene, o);
  for (std::size_t k = 0; k < plans.size(); ++k) {
    EXPECT_EQ(prepared.objects[k].sumTolerance, plans[k].sumTolerance);
    EXPECT_EQ(prepared.objects[k].sharpestLobe, plans[k].sharpestLobe);
    EXPECT_EQ(prepared.objects[k].plan, describePlan(plans[k], k == 2, RotationMethod::Fused));
  }
}

TEST(ObjectLevels, EachObjectByItsMaterialWithinTheCapTheGroundAtTheFloor) {
  Scene scene = defaultScene();  // phong:64 sphere, ggx:0.3 torus, ground
  EXPECT_EQ(levelsOf(planObjects(scene, options(7, true))), (std::vector<int>{7, 6, kAutoLevelFloor}));
  EXPECT_EQ(levelsOf(planObjects(scene, options(6, true))), (std::vector<int>{6, 6, kAutoLevelFloor}));
  EXPECT_EQ(levelsOf(planObjects(scene, options(3, true))), (std::vector<int>{3, 3, 3})) << "a cap under the floor";
  scene.objects[0].material = materialFromSpec("lambert");
  EXPECT_EQ(levelsOf(planObjects(scene, options(6, true))), (std::vector<int>{kAutoLevelFloor, 6, kAutoLevelFloor}));
  EXPECT_EQ(levelsOf(planObjects(scene, options(6, false))), (std::vector<int>{6, 6, 6})) << "fixed";
  RenderOptions haar = options(6, true);
  haar.method = RotationMethod::Haar;
  EXPECT_EQ(levelsOf(planObjects(scene, haar)), (std::vector<int>{6, 6, 6})) << "one level for the other methods";
  // fused measures its objects' lobes (the lobe path's choice reuses them); not the ground's.
  const std::vector<ObjectPlan> fused = planObjects(scene, options(5, false));
  EXPECT_EQ(fused[0].lobes.size(), 8u);
  EXPECT_TRUE(fused[2].lobes.empty());
}

TEST(ObjectLevels, ChoicesParseNameAndApply) {
  EXPECT_EQ(parseLevelChoice("5"), (LevelChoice{5, false}));
  EXPECT_EQ(parseLevelChoice("auto"), (LevelChoice{kDefaultLevelCap, true}));
  EXPECT_EQ(parseLevelChoice("auto:7"), (LevelChoice{7, true}));
  for (const char* bad : {"", "1", "8", "auto:", "auto:9", "auto:x", "automatic", "5x", "-5", "auto6"})
    EXPECT_FALSE(parseLevelChoice(bad).has_value()) << bad;
  EXPECT_EQ((LevelChoice{5, false}).name(), "5");
  EXPECT_EQ((LevelChoice{kDefaultLevelCap, true}).name(), "auto");
  EXPECT_EQ((LevelChoice{7, true}).name(), "auto:7");
  RenderOptions o;
  applyLevelChoice(o, {7, true});
  EXPECT_TRUE(o.automaticLevel);
  EXPECT_EQ(o.level, 7);
  o.method = RotationMethod::Haar;
  applyLevelChoice(o, {7, true});
  EXPECT_FALSE(o.automaticLevel) << "the other methods keep one level";
  EXPECT_EQ(o.level, kDefaultFixedLevel);
  applyLevelChoice(o, {6, false});
  EXPECT_EQ(o.level, 6);
  EXPECT_EQ(describeLevels({5, 5}), "level 5");
  EXPECT_EQ(describeLevels({6, 5, 4}), "levels 6, 5, 4");
}

// Everything of an object is at its level (slices, visibility, light,
// lobes) and the point lights are the same at every level, so a frame of
// objects at their own levels is, object by object, the frame at that
// object's level: exactly, pixel for pixel.
TEST(ObjectLevels, EachObjectIsDrawnAsAtItsOwnLevelAlone) {
  const Scene scene = twoObjects();
  const auto mixed = makeCpuRenderer(scene, options(6, true));
  ASSERT_EQ(mixed->objectLevels(), (std::vector<int>{5, 6}));
  FrameRequest request;
  request.width = request.height = 40;
  request.camera = scene.camera;
  const Frame a = mixed->render(request);
  const Frame six = makeCpuRenderer(scene, options(6, false))->render(request);
  const Frame five = makeCpuRenderer(scene, options(5, false))->render(request);
  std::size_t left = 0, right = 0, differs = 0;
  for (int y = 0; y < request.height; ++y) {
    for (int x = 0; x < request.width; ++x) {
      const std::size_t p = static_cast<std::size_t>(y * request.width + x);
      ASSERT_EQ(a.objectMask[p], six.objectMask[p]);
      if (!a.objectMask[p]) continue;
      const Frame& alone = x < request.width / 2 ? five : six;  // the sphere at 5 on the left, the torus at 6
      (x < request.width / 2 ? left : right)++;
      for (int c = 0; c < 3; ++c) EXPECT_EQ(a.image.at(y, x, c), alone.image.at(y, x, c)) << x << ", " << y;
      if (six.image.at(y, x, 0) != five.image.at(y, x, 0)) ++differs;
    }
  }
  EXPECT_GT(left, 100u);
  EXPECT_GT(right, 100u);
  EXPECT_GT(differs, (left + right) / 2) << "levels 5 and 6 differ: the test can tell which one drew a pixel";
}

// The point lights read a narrow lobe from a finer table (object_levels.h
// pointLightLevel): the phong:64 sphere at level 6 from level 7's, which
// is built beside its own; the ggx:0.3 torus, whose lobe its own level
// resolves, and the ground (closed form) from their own.
TEST(ObjectLevels, PointLightsReadAFinerTableWhereTheLobeIsNarrow) {
  const Scene scene = defaultScene();  // phong:64 sphere, ggx:0.3 torus, ground
  const PreparedScene p = prepareScene(scene, options(6, true));
  ASSERT_FALSE(p.pointLights.empty()) << "the default sky has a sun";
  EXPECT_EQ(p.objects[0].level, 6);
  EXPECT_EQ(p.objects[0].pointLevel, 7);
  EXPECT_EQ(p.objects[0].pointTable.level(), 7);
  EXPECT_EQ(p.objects[0].pointTable.thetaSamples(), p.objects[0].table.thetaSamples());
  EXPECT_EQ(p.objects[1].pointLevel, p.objects[1].level);
  EXPECT_EQ(p.objects[1].pointTable.storedBytes(), 0u) << "no second table where the first serves";
  EXPECT_EQ(p.objects[2].pointLevel, p.objects[2].level);
  EXPECT_EQ(pointLightLevel({}, 5), 5) << "no lobes measured";
  const std::vector<ObjectPlan> levels = planObjects(scene, options(7, false));
  EXPECT_EQ(pointLightLevel(levels[0].lobes, 7), 7) << "never past the finest level";
  EXPECT_EQ(pointLightLevel(levels[1].lobes, 4), 6) << "a coarse object's lights read the level its lobe needs";
}

TEST(ObjectLevels, TheRestLightIsKeptAtTheLevelsInUseOnly) {
  const PreparedScene p = prepareScene(twoObjects(), options(6, true));
  // The objects' levels, and those their light is turned from (two finer).
  for (const int level : {5, 6, 7}) EXPECT_EQ(p.restLightAt(level)[0].level(), level);
  EXPECT_EQ(lightTurnLevel(5), 7);
  EXPECT_EQ(lightTurnLevel(6), 7);
  EXPECT_THROW((void)p.restLightAt(4), std::out_of_range);
  EXPECT_THROW((void)p.restLightAt(8), std::out_of_range);
  EXPECT_EQ(p.objects[0].visibilityBits.level(), 5);
  EXPECT_EQ(p.objects[1].visibilityBits.level(), 6);
  EXPECT_EQ(p.objects[0].table.level(), 5);
  // Both keep the integral of the backdrop's rest (solid-angle means).
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(p.restLightAt(5)[c].integral(), p.restLightAt(6)[c].integral(), 1e-4 * p.restLightAt(6)[c].integral());
}

}  // namespace
}  // namespace haarcast::render
