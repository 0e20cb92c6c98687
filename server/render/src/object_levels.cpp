// A map level per object (object_levels.h).
#include "haarcast/render/object_levels.h"

#include <algorithm>
#include <cstdio>

#include "haarcast/core/lobe.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/shared_smooth.h"
#include "haarcast/render/renderer.h"
#include "haarcast/core/splitsum.h"

namespace haarcast::render {

std::vector<ObjectPlan> planObjects(const Scene& scene, const RenderOptions& options) {
  std::vector<ObjectPlan> out(scene.objects.size());
  const bool fused = options.method == RotationMethod::Fused;
  const std::vector<double> thetaOut = lobeThetaOut(options.thetaSamples);  // the slice table's θₒ (BrdfSliceTable::build)
  for (std::size_t k = 0; k < out.size(); ++k) {
    const SceneObject& object = scene.objects[k];
    ObjectPlan& o = out[k];
    o.level = options.level;
    if (!fused) continue;
    if (object.ground) {
      if (options.automaticLevel) o.level = std::min(kAutoLevelFloor, options.level);
      continue;
    }
    o.lobes = measureLobes(*object.material.brdf, thetaOut);
    o.sharpestLobe = static_cast<float>(sharpestMedian(o.lobes));
    if (options.automaticLevel) o.level = chooseLevel(*object.material.brdf, thetaOut, o.lobes, options.level);
    if (shared::sumsByCells(static_cast<shared::uint>(o.level), options.sumTolerance)) o.sumTolerance = options.sumTolerance;
    o.smoothSumTolerance = options.smoothSumTolerance;
  }
  return out;
}

std::string describePlan(const ObjectPlan& plan, bool ground, RotationMethod method) {
  if (method != RotationMethod::Fused) return "level " + std::to_string(plan.level);
  if (ground) return "closed form";
  char text[160];
  int n = std::snprintf(text, sizeof text, "level %d, ", plan.level);
  if (plan.sumTolerance > 0.0f) n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n), "cells τ %g", static_cast<double>(plan.sumTolerance));
  else n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n), "every direction");
  if (plan.smoothSumTolerance > 0.0f) {
    std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n), ", a neighbour's sum within %.1f°",
                  static_cast<double>(shared::kSmoothSumLobeShare * plan.sharpestLobe) * 180.0 / kPi);
  }
  return text;
}

int pointLightLevel(std::span<const shared::SliceLobe> lobes, int level) {
  if (lobes.empty()) return level;
  return std::max(level, chooseLevel(lobes, static_cast<int>(shared::kFusedMaxLevel), level));
}

std::string LevelChoice::name() const {
  if (!automatic) return std::to_string(level);
  return level == kDefaultLevelCap ? "auto" : "auto:" + std::to_string(level);
}

std::optional<LevelChoice> parseLevelChoice(std::string_view text) {
  auto level = [](std::string_view digits) -> std::optional<int> {
    if (digits.empty() || digits.size() > 2) return std::nullopt;
    int v = 0;
    for (const char c : digits) {
      if (c < '0' || c > '9') return std::nullopt;
      v = 10 * v + (c - '0');
    }
    if (v < kMinRenderLevel || v > kMaxRenderLevel) return std::nullopt;
    return v;
  };
  if (text == "auto") return LevelChoice{kDefaultLevelCap, true};
  if (text.starts_with("auto:")) {
    const std::optional<int> cap = level(text.substr(5));
    if (!cap) return std::nullopt;
    return LevelChoice{*cap, true};
  }
  const std::optional<int> fixed = level(text);
  if (!fixed) return std::nullopt;
  return LevelChoice{*fixed, false};
}

std::string levelChoiceHelp() {
  const std::string range = std::to_string(kMinRenderLevel) + ".." + std::to_string(kMaxRenderLevel);
  return "N (" + range + ": every object at level N), auto (fused: each object its own level by its material, at most " +
         std::to_string(kDefaultLevelCap) + "; the other methods " + std::to_string(kDefaultFixedLevel) +
         ") or auto:CAP (at most CAP, " + range + ")";
}

void applyLevelChoice(RenderOptions& options, const LevelChoice& choice) {
  options.automaticLevel = choice.automatic && options.method == RotationMethod::Fused;
  options.level = choice.automatic && options.method != RotationMethod::Fused ? std::min(choice.level, kDefaultFixedLevel)
                                                                              : choice.level;
}

std::string describeLevels(const std::vector<int>& objectLevels) {
  const std::vector<int> distinct = levelsInUse(objectLevels);
  if (distinct.size() == 1) return "level " + std::to_string(distinct.front());
  std::string out = "levels ";
  for (std::size_t k = 0; k < objectLevels.size(); ++k) out += (k ? ", " : "") + std::to_string(objectLevels[k]);
  return out;
}

std::vector<int> levelsInUse(const std::vector<int>& objectLevels) {
  std::vector<int> levels = objectLevels;
  std::sort(levels.begin(), levels.end());
  levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
  return levels;
}

}  // namespace haarcast::render
