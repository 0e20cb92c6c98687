#include "eval_assets.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/io/mesh_io.h"

namespace haarcast::app {

namespace fs = std::filesystem;

EvalAssets discoverAssets(const EvalOptions& o) {
  EvalAssets a;
  const fs::path data(o.dataDir);
  auto have = [&](const fs::path& p) { return !o.dataDir.empty() && fs::is_regular_file(data / p); };
  // The five probes standing in for the seed's five (DESIGN.md); cheap to
  // load, so --quick takes them all: each is a column of the seed's tables.
  for (const char* name : {"grace", "uffizi", "ennis", "pisa", "wells"}) {
    const fs::path p = fs::path("probes") / (std::string(name) + "_latlong_256x128.hdr");
    if (have(p)) a.environments.emplace_back(name, render::environmentFromFile((data / p).string()));
  }
  if (a.environments.empty()) {
    a.environments.emplace_back("builtin-sky", render::builtinEnvironment());
    a.notes.push_back("no probes found: the built-in sky stands in for the five environments");
  }
  // Models: the seed's sphere, Easter (moai), Venus, bunny, cat; those named
  // by options.models alone when it is set.
  auto wanted = [&](const std::string& name) {
    return o.models.empty() || std::find(o.models.begin(), o.models.end(), name) != o.models.end();
  };
  for (const std::string& name : o.models) {
    const bool known = std::any_of(std::begin(kSeedModels), std::end(kSeedModels),
                                   [&](const auto& m) { return name == m.first; });
    if (!known) throw std::invalid_argument("eval: no model \"" + name + "\" (sphere, easter, venus, bunny, cat)");
  }
  std::vector<std::string> missing;
  for (const auto& [name, file] : kSeedModels) {
    if (!wanted(name)) continue;
    if (std::string(file).empty()) {  // the sphere is built in
      a.models.emplace_back(name, std::make_shared<Mesh>(assets::makeSphere(48)));
      continue;
    }
    const fs::path p = fs::path("meshes") / file;
    if (!have(p)) {
      missing.push_back(name);
      continue;
    }
    auto mesh = std::make_shared<Mesh>(io::loadMesh((data / p).string()));
    render::fitToUnitSphere(*mesh);
    a.models.emplace_back(name, mesh);
  }
  if (!missing.empty() && a.models.size() <= 1 && !o.quick) {
    a.models.emplace_back("torus", std::make_shared<Mesh>(assets::makeTorus(0.7, 0.3, 64, 32)));
    a.notes.push_back("no meshes found: a torus stands in for the seed's models");
  } else if (!missing.empty()) {
    std::string names;
    for (const auto& n : missing) names += (names.empty() ? "" : ", ") + n;
    a.notes.push_back("no mesh for " + names + (o.dataDir.empty() ? " (no data folder)" : " in the data folder") +
                      ": Tables 1–4 leave them out");
  }
  if (a.models.empty()) throw std::invalid_argument("eval: none of the models asked for could be loaded");
  // The glossiness grid's model: the bunny, as in the seed's figure, when it is here.
  const auto bunny = std::find_if(a.models.begin(), a.models.end(), [](const auto& m) { return m.first == "bunny"; });
  a.glossModelName = bunny != a.models.end() ? bunny->first : a.models.front().first;
  a.glossModel = bunny != a.models.end() ? bunny->second : a.models.front().second;
  auto material = [&](const char* file, const char* fallback) {
    const fs::path p = fs::path("brdfs") / file;
    if (have(p)) return render::materialFromSpec((data / p).string());
    a.notes.push_back(std::string("no ") + file + ": " + fallback + " stands in");
    return render::materialFromSpec(fallback);
  };
  a.tableMaterials.emplace_back("alum-bronze", material("alum-bronze-sgd.binary", "ggx:0.3"));
  a.tableMaterials.emplace_back("blue-metallic-paint", material("blue-metallic-paint-sgd.binary", "phong:64"));
  a.glossMaterials.emplace_back("steel", material("chrome-steel-sgd.binary", "phong:512"));
  a.glossMaterials.push_back(a.tableMaterials[1]);
  a.glossMaterials.push_back(a.tableMaterials[0]);
  return a;
}

render::Scene singleObjectScene(const render::Environment& env, const std::string& name, std::shared_ptr<Mesh> mesh,
                                const render::Material& m, const glm::dvec3& rotateDegrees) {
  render::Scene s;
  s.environment = env;
  render::SceneObject o{name, std::move(mesh), m, {}};
  o.pose.rotateDegrees = rotateDegrees;
  s.objects.push_back(o);
  s.camera.eye = {0.0, 0.0, 3.0};
  s.camera.fovYDegrees = 42.0;
  return s;
}

ErrorStats objectError(const render::RenderResult& reference, const io::RgbImage& test,
                       const std::vector<std::uint8_t>& mask) {
  std::vector<double> ref, got;
  for (std::size_t i = 0; i < mask.size(); ++i) {
    if (!mask[i]) continue;
    for (int c = 0; c < 3; ++c) {
      ref.push_back(reference.image.rgb[3 * i + static_cast<std::size_t>(c)]);
      got.push_back(test.rgb[3 * i + static_cast<std::size_t>(c)]);
    }
  }
  if (ref.empty()) throw std::runtime_error("eval: the object covers no pixel");
  ErrorStats e = compareSignals(ref, got);
  if (!std::isfinite(e.psnr)) e.psnr = 300.0;
  return e;
}

}  // namespace haarcast::app
