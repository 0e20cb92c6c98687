#include "serve_catalog.h"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

namespace haarcast::app {

namespace fs = std::filesystem;

ServeCatalog buildServeCatalog(const std::vector<ServedScene>& scenes, const std::string& materialsDir) {
  ServeCatalog out;
  out.catalog.materials = kBuiltinMaterials;
  if (!materialsDir.empty()) {
    std::error_code ec;
    if (!fs::is_directory(materialsDir, ec)) throw std::invalid_argument("--materials-dir " + materialsDir + " is not a folder");
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(materialsDir)) {
      if (entry.is_regular_file() && entry.path().extension() == ".binary") files.push_back(entry.path());
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      const std::string name = "merl:" + f.stem().string();
      out.materialFiles[name] = f.string();
      out.catalog.materials.push_back(name);
    }
  }
  for (const auto& s : scenes) {
    net::Catalog::SceneEntry entry;
    entry.name = s.name;
    entry.camera = s.scene.camera;
    for (const auto& o : s.scene.objects) {
      // A scene file's MERL material is named "merl:STEM" (render::materialFromSpec).
      entry.defaultMaterials.push_back(o.material.name);
      entry.objectNames.push_back(o.name);
      entry.poses.push_back(o.pose);
    }
    out.catalog.scenes.push_back(std::move(entry));
  }
  return out;
}

}  // namespace haarcast::app
