#include "haarcast/render/scene.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/trigonometric.hpp>
#include <nlohmann/json.hpp>

#include "haarcast/assets/procedural_environment.h"
#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/assets/suns_environment.h"
#include "haarcast/io/environment.h"
#include "haarcast/io/input_file.h"
#include "haarcast/io/merl.h"
#include "haarcast/io/mesh_io.h"
#include "haarcast/io/slice_cache.h"

namespace haarcast::render {

namespace fs = std::filesystem;

void rotateEnvironment(Environment& environment, const glm::dmat3& rotation) {
  environment.rotation = rotation * environment.rotation;
  if (environment.radiance) {
    // L(ω) = L_before(Rᵀω): what came from Rᵀω now comes from ω.
    environment.radiance = [radiance = std::move(environment.radiance), inverse = glm::transpose(rotation)](
                               const glm::dvec3& d) { return radiance(inverse * d); };
  }
}

glm::dmat3 Pose::rotation() const {
  const glm::dvec3 r = glm::radians(rotateDegrees);
  const glm::dmat4 m = glm::rotate(glm::rotate(glm::rotate(glm::dmat4(1.0), r.z, {0, 0, 1}), r.y, {0, 1, 0}), r.x,
                                   {1, 0, 0});
  return glm::dmat3(m);
}

glm::dmat4 Pose::objectToWorld() const {
  glm::dmat4 m(rotation() * scale);
  m[3] = glm::dvec4(translate, 1.0);
  return m;
}

Environment builtinEnvironment() {
  Environment e;
  e.name = "builtin sky";
  e.radiance = [](const glm::dvec3& d) { return assets::proceduralEnvironmentRadiance(d); };
  e.maps = [](int level) { return assets::proceduralEnvironment(level, 8); };
  return e;
}

Environment sunsEnvironment() {
  Environment e;
  e.name = "builtin suns";
  e.radiance = [](const glm::dvec3& d) { return assets::sunsEnvironmentRadiance(d); };
  e.maps = [](int level) { return assets::sunsEnvironment(level); };
  return e;
}

Environment constantEnvironment(double radiance) {
  Environment e;
  e.name = "constant";
  e.radiance = [radiance](const glm::dvec3&) { return glm::dvec3(radiance); };
  e.maps = [radiance](int level) {
    const auto v = static_cast<float>(radiance);
    return std::array<SphereMap, 3>{SphereMap(level, v), SphereMap(level, v), SphereMap(level, v)};
  };
  return e;
}

Environment environmentFromFile(const std::string& path, const std::string& layout) {
  auto image = std::make_shared<io::RgbImage>(io::loadEnvironment(path, io::parseProbeLayout(layout)));
  Environment e;
  e.name = fs::path(path).filename().string();
  // Per direction: bilinear in the haarcast lat-long image (row 0 at θ = 0).
  e.radiance = [image](const glm::dvec3& d) {
    const Spherical s = directionToSpherical(d);
    const double y = std::clamp(s.theta / kPi * image->height - 0.5, 0.0, image->height - 1.0);
    const double x = s.phi / kTwoPi * image->width - 0.5;
    const int r0 = static_cast<int>(y), r1 = std::min(r0 + 1, image->height - 1);
    const int cw = static_cast<int>(std::floor(x));
    const int c0 = ((cw % image->width) + image->width) % image->width, c1 = (c0 + 1) % image->width;
    const double ty = y - r0, tx = x - std::floor(x);
    glm::dvec3 out(0.0);
    for (int c = 0; c < 3; ++c) {
      const double top = (1 - tx) * image->at(r0, c0, c) + tx * image->at(r0, c1, c);
      const double bottom = (1 - tx) * image->at(r1, c0, c) + tx * image->at(r1, c1, c);
      out[c] = (1 - ty) * top + ty * bottom;
    }
    return out;
  };
  e.maps = [image](int level) { return io::environmentToMaps(*image, level); };
  return e;
}

Material materialFromSpec(const std::string& spec, const std::string& baseDir) {
  const auto colon = spec.find(':');
  const std::string kind = spec.substr(0, colon);
  auto number = [&](const char* what) {
    if (colon == std::string::npos) throw std::invalid_argument("material \"" + spec + "\": needs " + what);
    try {
      std::size_t used = 0;
      const double v = std::stod(spec.substr(colon + 1), &used);
      if (used != spec.size() - colon - 1) throw std::invalid_argument("trailing text");
      return v;
    } catch (const std::exception&) {
      throw std::invalid_argument("material \"" + spec + "\": " + what + " is not a number");
    }
  };
  Material m;
  m.name = spec;
  m.cacheKey = spec;
  // Analytic defaults: a warm metal-like specular with a little diffuse.
  const glm::dvec3 kd(0.06, 0.05, 0.04), ks(0.9, 0.75, 0.55);
  if (kind == "lambert") {
    m.brdf = makeLambert(glm::dvec3(kLambertAlbedo));
  } else if (kind == "phong") {
    m.brdf = makePhong(kd, ks, number("an exponent"));
  } else if (kind == "blinn-phong") {
    m.brdf = makeBlinnPhong(kd, ks, number("an exponent"));
  } else if (kind == "ggx") {
    m.brdf = makeGgx(kd, glm::dvec3(0.95, 0.64, 0.54), number("a roughness"));
  } else if (fs::path(spec).extension() == ".binary") {
    const std::string path = (fs::path(baseDir) / spec).string();
    // Measured tables may carry a few non-finite cells where φd is degenerate
    // (merl.h); repair them and say so rather than refuse the material.
    io::MerlLoadOptions load;
    load.repairNonFinite = true;
    auto merl = io::loadMerlBrdf(path, load);
    if (merl->repairedCells() > 0) {
      m.warning = path + ": repaired " + std::to_string(merl->repairedCells()) + " non-finite cells";
    }
    m.brdf = std::move(merl);
    m.cacheKey = io::fileCacheKey(path);
    // Named by its file's stem, as `serve --materials-dir` names its files:
    // the name reaches clients (SceneInfo), a path of the server must not.
    m.name = "merl:" + fs::path(spec).stem().string();
  } else {
    throw std::invalid_argument("material \"" + spec +
                                "\": expected lambert, phong:EXP, blinn-phong:EXP, ggx:ROUGHNESS or a MERL .binary file");
  }
  return m;
}

UpAxis parseUpAxis(const std::string& text) {
  if (text == "y" || text == "Y") return UpAxis::Y;
  if (text == "z" || text == "Z") return UpAxis::Z;
  throw std::invalid_argument("up axis \"" + text + "\" is not one of y, z");
}

void makeYUp(Mesh& mesh, UpAxis up) {
  if (up == UpAxis::Y) return;
  const auto turn = [](const glm::vec3& v) { return glm::vec3(v.x, v.z, -v.y); };
  for (glm::vec3& p : mesh.positions) p = turn(p);
  for (glm::vec3& n : mesh.normals) n = turn(n);
}

void fitToUnitSphere(Mesh& mesh) {
  const Bounds b = mesh.bounds();
  const double r = b.radius();
  if (!(r > 0.0)) throw std::invalid_argument("mesh \"" + mesh.name + "\" has no extent");
  const glm::dvec3 c = b.centre();
  for (glm::vec3& p : mesh.positions) p = glm::vec3((glm::dvec3(p) - c) / r);
}

void addGround(Scene& scene, const GroundOptions& options) {
  static_assert(GroundOptions{}.albedo == kLambertAlbedo);
  if (!(options.albedo >= 0.0 && options.albedo <= 1.0)) {
    throw std::invalid_argument("ground: albedo " + std::to_string(options.albedo) + " is outside [0, 1]");
  }
  if (!(options.extent > 0.0 && std::isfinite(options.extent))) {
    throw std::invalid_argument("ground: extent must be positive and finite");
  }
  if (scene.objects.empty()) throw std::invalid_argument("ground: the scene has no objects to stand under it");
  // The objects' world bounds at the scene's poses, from every vertex.
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (const SceneObject& o : scene.objects) {
    if (o.ground) throw std::invalid_argument("ground: the scene has one already (\"" + o.name + "\")");
    const glm::dmat4 m = o.pose.objectToWorld();
    for (const glm::vec3& p : o.mesh->positions) {
      const glm::dvec3 w(m * glm::dvec4(glm::dvec3(p), 1.0));
      lo = glm::min(lo, w);
      hi = glm::max(hi, w);
    }
  }
  const double radius = 0.5 * glm::length(hi - lo);
  SceneObject g;
  g.name = "ground";
  g.ground = true;
  g.groundAlbedo = glm::dvec3(options.albedo);
  // A finely divided plane: the G-buffer rasterises it like any mesh, and
  // vertex visibility (not used by fused's closed form) stays cheap.
  g.mesh = std::make_shared<Mesh>(assets::makePlane(1.0, 8));
  g.material = materialFromSpec("lambert");
  if (options.albedo != kLambertAlbedo) {
    char albedo[32];
    std::snprintf(albedo, sizeof albedo, "%g", options.albedo);
    g.material.name = std::string("lambert (albedo ") + albedo + ")";
    g.material.cacheKey = "lambert-albedo-" + std::string(albedo);
    g.material.brdf = makeLambert(g.groundAlbedo);
  }
  g.pose.scale = options.extent * std::max(radius, 1e-6);
  g.pose.translate = {0.5 * (lo.x + hi.x), lo.y, 0.5 * (lo.z + hi.z)};
  scene.objects.push_back(std::move(g));
}

Scene defaultScene() {
  Scene s;
  s.environment = builtinEnvironment();
  auto sphere = std::make_shared<Mesh>(assets::makeSphere(48));
  auto torus = std::make_shared<Mesh>(assets::makeTorus(0.6, 0.22, 64, 32));
  SceneObject a{"sphere", sphere, materialFromSpec("phong:64"), {}};
  a.pose.translate = {-0.75, 0.0, 0.0};
  a.pose.scale = 0.65;
  SceneObject b{"torus", torus, materialFromSpec("ggx:0.3"), {}};
  b.pose.translate = {0.8, 0.0, 0.0};
  b.pose.rotateDegrees = {60.0, 20.0, 0.0};
  s.objects = {a, b};
  // Both objects inside a square view with a margin, so no aspect ratio
  // crops them (a portrait frame keeps this field across its width).
  s.camera.eye = {0.0, 0.85, 4.8};
  s.camera.fovYDegrees = 45.0;
  addGround(s);
  return s;
}

namespace {

[[noreturn]] void fail(const std::string& file, const std::string& where, const std::string& what) {
  throw std::runtime_error(file + ": " + where + ": " + what);
}

glm::dvec3 vec3At(const nlohmann::json& j, const std::string& file, const std::string& where) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number()) {
    fail(file, where, "expected an array of three numbers");
  }
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

std::shared_ptr<Mesh> meshAt(const nlohmann::json& j, const std::string& file, const std::string& where,
                             const fs::path& base, bool fit, UpAxis up) {
  Mesh mesh;
  if (j.is_string()) {
    mesh = io::loadMesh((base / j.get<std::string>()).string());
  } else if (j.is_object() && j.contains("builtin") && j["builtin"].is_string()) {
    const std::string name = j["builtin"];
    if (name == "sphere") mesh = assets::makeSphere(48);
    else if (name == "torus") mesh = assets::makeTorus();
    else if (name == "box") mesh = assets::makeBox();
    else if (name == "plane") mesh = assets::makePlane(1.0, 8);
    else if (name == "pillars") mesh = assets::makePillars();
    else fail(file, where + ".builtin", "unknown built-in mesh \"" + name + "\" (sphere, torus, box, plane, pillars)");
  } else {
    fail(file, where, "expected a file name or {\"builtin\": …}");
  }
  makeYUp(mesh, up);
  if (fit) fitToUnitSphere(mesh);
  return std::make_shared<Mesh>(std::move(mesh));
}

Scene sceneFromJson(const nlohmann::json& j, const std::string& path, const SceneLimits& limits);

}  // namespace

void checkObjectCount(std::size_t objects, const SceneLimits& limits) {
  if (objects > limits.maxObjects) {
    throw std::invalid_argument("the scene has " + std::to_string(objects) + " objects, over the limit of " +
                                std::to_string(limits.maxObjects) + " (--max-scene-objects)");
  }
}

Scene loadScene(const std::string& path, const SceneLimits& limits) {
  io::requireRegularFile(path, "scene file");
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open scene file");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    // parse_error, and out_of_range for a number no double holds (1e99999).
    throw std::runtime_error(path + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) fail(path, "top level", "expected an object");
  try {
    return sceneFromJson(j, path, limits);
  } catch (const nlohmann::json::exception& e) {
    // A value of the wrong type where a field is read ("fov_y": "wide").
    throw std::runtime_error(path + ": " + e.what());
  }
}

namespace {

Scene sceneFromJson(const nlohmann::json& j, const std::string& path, const SceneLimits& limits) {
  const fs::path base = fs::path(path).parent_path();
  Scene s;
  s.environment = builtinEnvironment();
  if (j.contains("environment")) {
    const auto& e = j["environment"];
    if (e.contains("file")) {
      s.environment = environmentFromFile((base / e["file"].get<std::string>()).string(), e.value("layout", "auto"));
    } else if (e.value("builtin", "") == "suns") {
      s.environment = sunsEnvironment();
    } else if (e.value("builtin", "") != "sky") {
      fail(path, "environment", "expected {\"file\": …} or {\"builtin\": \"sky\"|\"suns\"}");
    }
    if (e.contains("rotate")) {
      Pose turn;
      turn.rotateDegrees = vec3At(e["rotate"], path, "environment.rotate");
      rotateEnvironment(s.environment, turn.rotation());
    }
  }
  if (j.contains("camera")) {
    const auto& c = j["camera"];
    if (c.contains("eye")) s.camera.eye = vec3At(c["eye"], path, "camera.eye");
    if (c.contains("target")) s.camera.target = vec3At(c["target"], path, "camera.target");
    if (c.contains("up")) s.camera.up = vec3At(c["up"], path, "camera.up");
    if (c.contains("fov_y")) s.camera.fovYDegrees = c["fov_y"].get<double>();
    if (!(s.camera.fovYDegrees > 1.0 && s.camera.fovYDegrees < 179.0)) fail(path, "camera.fov_y", "must be in (1, 179) degrees");
  }
  if (!j.contains("objects") || !j["objects"].is_array() || j["objects"].empty()) {
    fail(path, "objects", "expected a non-empty array");
  }
  // Before any mesh is read: the count alone can be the problem.
  try {
    checkObjectCount(j["objects"].size() + (j.contains("ground") ? 1 : 0), limits);
  } catch (const std::invalid_argument& e) {
    fail(path, "objects", e.what());
  }
  for (std::size_t k = 0; k < j["objects"].size(); ++k) {
    const auto& o = j["objects"][k];
    const std::string where = "objects[" + std::to_string(k) + "]";
    if (!o.contains("mesh")) fail(path, where, "missing \"mesh\"");
    if (!o.contains("material") || !o["material"].is_string()) fail(path, where, "missing \"material\" string");
    SceneObject obj;
    obj.name = o.value("name", "object" + std::to_string(k));
    UpAxis up = UpAxis::Y;
    if (o.contains("up")) {
      if (!o["up"].is_string()) fail(path, where + ".up", "expected \"y\" or \"z\"");
      try {
        up = parseUpAxis(o["up"].get<std::string>());
      } catch (const std::invalid_argument& e) {
        fail(path, where + ".up", e.what());
      }
    }
    try {
      obj.mesh = meshAt(o["mesh"], path, where + ".mesh", base, o.value("fit", true), up);
      obj.material = materialFromSpec(o["material"].get<std::string>(), base.string());
    } catch (const std::invalid_argument& e) {
      fail(path, where, e.what());
    }
    if (o.contains("rotate")) obj.pose.rotateDegrees = vec3At(o["rotate"], path, where + ".rotate");
    if (o.contains("translate")) obj.pose.translate = vec3At(o["translate"], path, where + ".translate");
    obj.pose.scale = o.value("scale", 1.0);
    if (!(obj.pose.scale > 0.0)) fail(path, where + ".scale", "must be positive");
    s.objects.push_back(std::move(obj));
  }
  // "ground": true, false (the default), or {"albedo": a, "extent": e}.
  if (j.contains("ground")) {
    const auto& g = j["ground"];
    GroundOptions ground;
    bool on = true;
    if (g.is_boolean()) {
      on = g.get<bool>();
    } else if (g.is_object()) {
      for (const auto& [key, value] : g.items()) {
        if (key != "albedo" && key != "extent") fail(path, "ground", "unknown key \"" + key + "\" (albedo, extent)");
        if (!value.is_number()) fail(path, "ground." + key, "expected a number");
      }
      ground.albedo = g.value("albedo", ground.albedo);
      ground.extent = g.value("extent", ground.extent);
    } else {
      fail(path, "ground", "expected true, false or {\"albedo\": …, \"extent\": …}");
    }
    if (on) {
      try {
        addGround(s, ground);
      } catch (const std::invalid_argument& e) {
        fail(path, "ground", e.what());
      }
    }
  }
  return s;
}

}  // namespace

}  // namespace haarcast::render
