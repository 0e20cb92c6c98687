// What `haarcast serve` offers its clients, from its flags: the scenes by
// name, each object's name, pose and own material, the materials a client
// may choose (the analytic ones, and `merl:NAME` for each NAME.binary of
// --materials-dir and of --data's brdfs/), and the probes and meshes of
// --data (probes/ and meshes/, by file stem). Everything here reaches
// clients in Welcome and SceneInfo, so it names things as the user did (a
// scene file's stem, a material spec, `merl:STEM`, a probe's or a mesh's
// stem) and never holds a path of the server; the paths stay in
// `materialFiles` and `probeFiles`, which only the renderer builder reads
// (servedScene).
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include "haarcast/net/protocol.h"
#include "haarcast/render/scene.h"

namespace haarcast::app {

// The analytic materials every server offers.
inline const std::vector<std::string> kBuiltinMaterials = {"lambert",  "phong:16", "phong:64",
                                                           "phong:256", "ggx:0.1",  "ggx:0.3"};

// The probe files a --data folder's probes/ may hold: what the scene
// loader reads for "environment": {"file": …} (io::readImage).
inline const std::vector<std::string> kProbeExtensions = {".exr", ".hdr", ".pic", ".rgbe", ".pfm"};
// The mesh files of its meshes/: what io::loadMesh reads.
inline const std::vector<std::string> kMeshExtensions = {".ply", ".obj"};

struct ServedScene {
  std::string name;  // "default", or a --scene file's stem
  render::Scene scene;
};

struct ServeCatalog {
  net::Catalog catalog;                              // backends are the caller's to add
  std::map<std::string, std::string> materialFiles;  // offered "merl:NAME" → its file
  std::map<std::string, std::string> probeFiles;     // offered probe name → its file
  // Offered mesh name → its mesh scene (app::meshScene, on a ground) stood up
  // along Y ([0]) and along Z ([1]), under the built-in environment.
  std::map<std::string, std::array<render::Scene, 2>> meshScenes;
};

// Throws std::invalid_argument naming the flag and the file or folder: a
// --materials-dir or --data that is not a folder, a --data with none of
// probes/, meshes/ and brdfs/, two files of one name, a probe or mesh that
// does not load (each is read once here, so a session never meets one), a
// mesh over `limits`.
ServeCatalog buildServeCatalog(const std::vector<ServedScene>& scenes, const std::string& materialsDir,
                               const std::string& dataDir = {}, const render::SceneLimits& limits = {});

// What a session's config draws: its scene, or the mesh scene of its mesh
// under its scene's environment; its probe's environment instead when it
// names one; each object's material as chosen (offered names turned back
// into files). Throws std::invalid_argument for a name `served` does not
// offer (protocol.cpp refuses those before any build).
render::Scene servedScene(const std::vector<ServedScene>& scenes, const ServeCatalog& served,
                          const net::SessionConfig& config);

}  // namespace haarcast::app
