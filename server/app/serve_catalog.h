// What `haarcast serve` offers its clients, from its flags: the scenes by
// name, each object's name, pose and own material, and the materials a
// client may choose (the analytic ones, and `merl:NAME` for each
// NAME.binary of --materials-dir). Everything here reaches clients in
// Welcome and SceneInfo, so it names things as the user did (a scene file's
// stem, a material spec or `merl:STEM`) and never holds a path of the
// server; the paths stay in `materialFiles`, which only the renderer
// builder reads.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "haarcast/net/protocol.h"
#include "haarcast/render/scene.h"

namespace haarcast::app {

// The analytic materials every server offers.
inline const std::vector<std::string> kBuiltinMaterials = {"lambert",  "phong:16", "phong:64",
                                                           "phong:256", "ggx:0.1",  "ggx:0.3"};

struct ServedScene {
  std::string name;  // "default", or a --scene file's stem
  render::Scene scene;
};

struct ServeCatalog {
  net::Catalog catalog;                              // backends are the caller's to add
  std::map<std::string, std::string> materialFiles;  // offered "merl:NAME" → its file
};

// Throws std::invalid_argument for a --materials-dir that is not a folder.
ServeCatalog buildServeCatalog(const std::vector<ServedScene>& scenes, const std::string& materialsDir);

}  // namespace haarcast::app
