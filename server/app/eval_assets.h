// What `haarcast eval` renders: the seed's probes, models and materials from
// a data folder (../shared/data's layout), with built-in stand-ins for what
// is missing, and the one-object scene every seed experiment uses.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "eval.h"
#include "haarcast/core/metrics.h"
#include "haarcast/core/mesh.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/scene.h"

namespace haarcast::app {

template <typename T>
using NamedList = std::vector<std::pair<std::string, T>>;

struct EvalAssets {
  NamedList<render::Environment> environments;  // grace, uffizi, ennis, pisa, wells (the seed's five, DESIGN.md)
  NamedList<std::shared_ptr<Mesh>> models;      // Tables 1–4: sphere, easter, venus, bunny, cat
  NamedList<render::Material> tableMaterials;   // Tables 1–4: the seed's two
  NamedList<render::Material> glossMaterials;   // glossiness grid: steel, blue paint, aluminium bronze
  std::shared_ptr<Mesh> glossModel;             // the glossiness grid's: the bunny when the data has one
  std::string glossModelName;
  std::vector<std::string> notes;               // what was substituted or left out
};

// The models of Tables 1–4 are options.models when set (names from
// kSeedModels; "sphere" is built in), else all that the data folder has.
EvalAssets discoverAssets(const EvalOptions& options);

// The seed's five models, in its order: name and file under meshes/ (the
// sphere is built in).
inline constexpr std::pair<const char*, const char*> kSeedModels[] = {
    {"sphere", ""}, {"easter", "moai.obj"}, {"venus", "venus.obj"}, {"bunny", "bunny.ply"}, {"cat", "cat-low-resolution.obj"}};

// One object at the origin in front of a camera that it nearly fills; named
// after its model, so that progress lines say which mesh is being prepared.
render::Scene singleObjectScene(const render::Environment& env, const std::string& name, std::shared_ptr<Mesh> mesh,
                                const render::Material& m, const glm::dvec3& rotateDegrees);

// DESIGN.md PSNR over the object's pixels of linear RGB. An exact match is
// capped at 300 dB so that averages stay finite (and is rare: float noise).
ErrorStats objectError(const render::RenderResult& reference, const io::RgbImage& test,
                       const std::vector<std::uint8_t>& mask);

}  // namespace haarcast::app
