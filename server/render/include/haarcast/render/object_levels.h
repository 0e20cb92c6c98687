// `fused`'s map level per object (RenderOptions::automaticLevel), chosen
// from each object's material before anything else is prepared: the slice
// tables, the visibility bits (and their refinement) and each frame's light
// of an object are then all at its level, and a rough object no longer pays
// for the level a near-mirror beside it needs (docs/design.md, "A level per
// object"). The rule is core/lobe.h chooseLevel.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "haarcast/core/shared_layout.h"
#include "haarcast/render/render_options.h"
#include "haarcast/render/scene.h"

namespace haarcast::render {

// How an object's pixels are drawn, decided once, from one measure of its
// material (its lobes), before anything is prepared: the map level and
// what a pixel spends there. The light's rest and the visibility then
// decide per pixel within it: which cells are summed fine (their detail and
// V; shared_cells.h) and whether the pixel's sum comes from its neighbours
// (their sums, and the point lights they show; shared_smooth.h).
struct ObjectPlan {
  int level = 0;
  // `fused`: its lobes measured whole at the slice table's θₒ (core
  // measureLobes), from which the level and the lobe path are chosen; empty
  // for the ground (shaded in closed form) and for the other methods.
  std::vector<shared::SliceLobe> lobes;
  // `fused`: its sharpest slice's median lobe angle (core sharpestMedian;
  // π without lobes): the level spans it with K texels (chooseLevel), and
  // a pixel may take its neighbours' sum where their mirror directions are
  // within half of it (shared_smooth.h).
  float sharpestLobe = 3.14159265f;
  // `fused`: the cells' tolerance (RenderOptions::sumTolerance where the
  // object is summed by cells, else 0: the ground, shaded in closed form,
  // and levels below shared::kCellMinLevel).
  float sumTolerance = 0.0f;
  // `fused`: RenderOptions::smoothSumTolerance where its pixels may take
  // their neighbours' sum, else 0 (the ground).
  float smoothSumTolerance = 0.0f;
};

// Per scene object, in order. Fixed (automaticLevel false) or a method
// other than `fused`: options.level for every object. Automatic:
// chooseLevel within [kAutoLevelFloor, options.level], the ground at the
// floor (its map light is one closed form, its pixels read no map).
std::vector<ObjectPlan> planObjects(const Scene& scene, const RenderOptions& options);

// A plan as the log says it: "level 6, cells τ 0.1, a neighbour's sum
// within 4.3°" (`fused`), "closed form" for the ground, "level 5" for the
// other methods.
std::string describePlan(const ObjectPlan& plan, bool ground, RotationMethod method);

// The level of an object's point-light slices (PreparedObject::pointLevel):
// a point light reads its slice at one direction, by Catmull-Rom over the
// texels' centres, so a lobe only two or three texels wide is read off its
// peak, and its highlight is misplaced and misshapen. The level of
// chooseLevel's step 1 up to shared::kFusedMaxLevel, at least the object's
// own `level`: a ggx:0.1 ball at level 6 reads its lights from level 7
// (docs/design.md, "Point lights read a narrow lobe from a finer table").
int pointLightLevel(std::span<const shared::SliceLobe> lobes, int level);

// The distinct levels of the objects, ascending.
std::vector<int> levelsInUse(const std::vector<int>& objectLevels);

// What a user or client asks for: one level for every object, or automatic
// levels up to a cap. `render` and `serve` default to automatic, cap 6:
// what a near-mirror gets (with the lobe path for its core), the level the
// service already allowed at most (net::Limits::maxLevel), level 7 costing
// 4× per pixel for what docs/evaluation.md ("A level per object") measures.
inline constexpr int kDefaultLevelCap = 6;
// The one level of the methods other than `fused` under automatic levels:
// the default they always had (their cost grows with the level as fused's
// does, and nothing chooses a level per object for them).
inline constexpr int kDefaultFixedLevel = 5;
struct LevelChoice {
  int level = kDefaultLevelCap;  // fixed: the level; automatic: the cap
  bool automatic = true;
  std::string name() const;      // "5", "auto" (the default cap) or "auto:7"
  bool operator==(const LevelChoice&) const = default;
};
// "N", "auto" or "auto:CAP" with N and CAP in kMinRenderLevel..kMaxRenderLevel;
// nullopt for anything else.
std::optional<LevelChoice> parseLevelChoice(std::string_view text);
// What the flags' help and errors say the valid choices are.
std::string levelChoiceHelp();
// options.level and automaticLevel for a choice and options.method: fused
// takes it as it is; another method under automatic levels takes
// min(cap, kDefaultFixedLevel), one level for every object.
void applyLevelChoice(RenderOptions& options, const LevelChoice& choice);
// "level 5" for one level, else "levels 4, 6" (each object's, in scene order).
std::string describeLevels(const std::vector<int>& objectLevels);

}  // namespace haarcast::render
