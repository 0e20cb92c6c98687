// A renderer build's stages, planned before it starts: what prepareScene
// and the backends will report through RenderProgress, in order, each with
// an estimate of its work. The server turns the stages' reports into one
// fraction of the whole build that never goes back, and an estimate of the
// time left (net/build_progress.h; docs/service.md, "Build progress").
//
// The work is in estimated seconds on one reference machine (2 cores), from
// a cost model per kind of stage (build_plan.cpp): only the ratios between
// stages matter for the fraction, and the estimate of the time left scales
// them by the rate this build measures. A slice table already in the cache
// is planned at a load's cost; visibility is planned as computed (its cache
// entry is known only by reading it), so a cached one ends at once and the
// fraction jumps past it.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "haarcast/render/render_options.h"
#include "haarcast/render/scene.h"

namespace haarcast::render {

// The stage of an object's point-light slices (PreparedObject::pointTable),
// built after every object's slices and visibility, once the light is split.
inline constexpr std::string_view kPointSlicesStage = "point slices";

struct PlannedStage {
  std::string name;   // as RenderProgress names it: "slices bunny", "visibility bunny" …
  double work = 0.0;  // estimated seconds on the reference machine, > 0
};

struct BuildPlan {
  std::vector<PlannedStage> stages;  // in the order they run
  double totalWork() const;
  bool empty() const { return stages.empty(); }
};

// The stages of makeRenderer(backend, scene, options) and, for "vulkan",
// the server's warm-up frame after it. Chooses the objects' levels as
// prepareScene does (fused's automatic levels measure each BRDF's lobes).
BuildPlan planBuild(const Scene& scene, const RenderOptions& options, std::string_view backend);

}  // namespace haarcast::render
