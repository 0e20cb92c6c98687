#include "serve_catalog.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>

#include "haarcast/core/check.h"
#include "haarcast/io/mesh_io.h"
#include "mesh_scene.h"

namespace haarcast::app {

namespace fs = std::filesystem;

namespace {

std::string lowerExtension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::string joinedNames(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// The regular files of `folder` whose extension is one of `extensions`
// (any case), sorted, as stem → file; two files of one stem are an error.
std::map<std::string, fs::path> filesByStem(const fs::path& folder, const std::vector<std::string>& extensions,
                                            const std::string& flag) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string ext = lowerExtension(entry.path());
    if (entry.is_regular_file() && std::find(extensions.begin(), extensions.end(), ext) != extensions.end()) {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  std::map<std::string, fs::path> out;
  for (const auto& f : files) {
    const auto [at, added] = out.emplace(f.stem().string(), f);
    if (!added) {
      throw std::invalid_argument(flag + ": " + at->second.string() + " and " + f.string() +
                                  " have one name, \"" + at->first + "\": rename one");
    }
  }
  return out;
}

// The MERL files of a folder as "merl:STEM" (--materials-dir, --data's brdfs/).
void addMaterials(ServeCatalog& out, const fs::path& folder, const std::string& flag) {
  for (const auto& [stem, file] : filesByStem(folder, {".binary"}, flag)) {
    const std::string name = "merl:" + stem;
    const auto [at, added] = out.materialFiles.emplace(name, file.string());
    if (!added) {
      throw std::invalid_argument(flag + ": " + file.string() + " is offered already as " + name + " (" + at->second + ")");
    }
    out.catalog.materials.push_back(name);
  }
}

net::Catalog::SceneEntry sceneEntry(const std::string& name, const render::Scene& scene) {
  net::Catalog::SceneEntry entry;
  entry.name = name;
  entry.camera = scene.camera;
  for (const auto& o : scene.objects) {
    // A scene file's MERL material is named "merl:STEM" (render::materialFromSpec).
    entry.defaultMaterials.push_back(o.material.name);
    entry.objectNames.push_back(o.name);
    entry.poses.push_back(o.pose);
  }
  return entry;
}

// --data's probes/: each read once now, so that a bad file stops the start
// with its name instead of failing a session's build.
void addProbes(ServeCatalog& out, const fs::path& folder) {
  for (const auto& [name, file] : filesByStem(folder, kProbeExtensions, "--data")) {
    try {
      render::environmentFromFile(file.string());
    } catch (const std::exception& e) {
      throw std::invalid_argument("--data: probe " + file.string() + " does not load: " + e.what());
    }
    out.probeFiles[name] = file.string();
    out.catalog.probes.push_back(name);
  }
}

// --data's meshes/: each read once, its up axis guessed from its bounds as
// the file has them, its mesh scene made both ways up (the ground's pose
// depends on it, and SceneInfo reports it before any build).
void addMeshes(ServeCatalog& out, const fs::path& folder, const render::SceneLimits& limits) {
  for (const auto& [name, file] : filesByStem(folder, kMeshExtensions, "--data")) {
    Mesh mesh;
    try {
      mesh = io::loadMesh(file.string());
    } catch (const std::exception& e) {
      throw std::invalid_argument("--data: mesh " + file.string() + " does not load: " + e.what());
    }
    if (mesh.triangles.size() > limits.maxTriangles) {
      throw std::invalid_argument("--data: mesh " + file.string() + " has " + std::to_string(mesh.triangles.size()) +
                                  " triangles, over --max-scene-triangles " + std::to_string(limits.maxTriangles));
    }
    net::Catalog::MeshEntry entry;
    entry.name = name;
    entry.guessedUp = guessUpAxis(mesh);
    auto& scenes = out.meshScenes[name];
    const render::Material material = render::materialFromSpec(kMeshMaterial);
    scenes[0] = meshScene(mesh, name, render::UpAxis::Y, material, {}, true);
    scenes[1] = meshScene(std::move(mesh), name, render::UpAxis::Z, material, {}, true);
    entry.upY = sceneEntry(name, scenes[0]);
    entry.upZ = sceneEntry(name, scenes[1]);
    out.catalog.meshes.push_back(std::move(entry));
  }
}

void addData(ServeCatalog& out, const std::string& dataDir, const render::SceneLimits& limits) {
  const fs::path root(dataDir);
  std::error_code ec;
  if (!fs::is_directory(root, ec)) throw std::invalid_argument("--data " + dataDir + " is not a folder");
  const bool probes = fs::is_directory(root / "probes", ec), meshes = fs::is_directory(root / "meshes", ec),
             brdfs = fs::is_directory(root / "brdfs", ec);
  if (!probes && !meshes && !brdfs) {
    throw std::invalid_argument("--data " + dataDir + " has none of the folders it is read for: probes/ (" +
                                joinedNames(kProbeExtensions) + "), meshes/ (" + joinedNames(kMeshExtensions) +
                                "), brdfs/ (MERL .binary)");
  }
  if (probes) addProbes(out, root / "probes");
  if (meshes) addMeshes(out, root / "meshes", limits);
  if (brdfs) addMaterials(out, root / "brdfs", "--data");
}

}  // namespace

ServeCatalog buildServeCatalog(const std::vector<ServedScene>& scenes, const std::string& materialsDir,
                               const std::string& dataDir, const render::SceneLimits& limits) {
  ServeCatalog out;
  out.catalog.materials = kBuiltinMaterials;
  if (!materialsDir.empty()) {
    std::error_code ec;
    if (!fs::is_directory(materialsDir, ec)) throw std::invalid_argument("--materials-dir " + materialsDir + " is not a folder");
    addMaterials(out, materialsDir, "--materials-dir");
  }
  if (!dataDir.empty()) addData(out, dataDir, limits);
  for (const auto& s : scenes) out.catalog.scenes.push_back(sceneEntry(s.name, s.scene));
  return out;
}

render::Scene servedScene(const std::vector<ServedScene>& scenes, const ServeCatalog& served,
                          const net::SessionConfig& c) {
  const auto it = std::find_if(scenes.begin(), scenes.end(), [&](const ServedScene& s) { return s.name == c.scene; });
  if (it == scenes.end()) throw std::invalid_argument("unknown scene \"" + c.scene + "\"");
  render::Scene scene = it->scene;
  if (!c.mesh.empty()) {
    const auto mesh = served.meshScenes.find(c.mesh);
    if (mesh == served.meshScenes.end()) throw std::invalid_argument("unknown mesh \"" + c.mesh + "\"");
    render::Environment environment = std::move(scene.environment);
    scene = mesh->second[c.up == render::UpAxis::Z ? 1 : 0];
    HC_CHECK_EQ(scene.objects.size(), std::size_t{2});  // the mesh and its ground, as the catalogue lists them
    scene.environment = std::move(environment);  // the mesh under the scene's light
  }
  if (!c.probe.empty()) {
    const auto probe = served.probeFiles.find(c.probe);
    if (probe == served.probeFiles.end()) throw std::invalid_argument("unknown probe \"" + c.probe + "\"");
    scene.environment = render::environmentFromFile(probe->second);
  }
  for (std::size_t i = 0; i < scene.objects.size() && i < c.materials.size(); ++i) {
    if (c.materials[i] == scene.objects[i].material.name) continue;  // the scene's own
    const auto file = served.materialFiles.find(c.materials[i]);
    scene.objects[i].material =
        render::materialFromSpec(file != served.materialFiles.end() ? file->second : c.materials[i]);
    scene.objects[i].material.name = c.materials[i];
  }
  return scene;
}

}  // namespace haarcast::app
