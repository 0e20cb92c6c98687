// The flags `render` and `reference` share: what to draw and where to write
// it. One definition, so the two commands always draw the same scene.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "haarcast/io/image.h"
#include "haarcast/render/scene.h"
#include "mesh_scene.h"  // kMeshMaterial

namespace haarcast::app {

struct SceneFlags {
  std::string scene, env, layout = "auto", mesh, material;
  std::vector<double> rotate;
  std::string up;  // with --mesh: y (empty: the same) or z
  int width = 128, height = 128;
  std::string background = "env";
  std::string out;
  std::optional<double> exposure;
  std::string tone = "reinhard";  // render::toneCurveName
  bool ground = false;  // with --mesh: a ground under it (render::addGround)
  render::SceneLimits limits;
};

// --max-scene-objects --max-scene-triangles --max-visibility-mb into `limits`.
void addSceneLimitFlags(CLI::App& command, render::SceneLimits& limits);

// --scene --env --env-layout --mesh --material --up --rotate --width --height
// --background --out --exposure --tone, and the scene limits
void addSceneFlags(CLI::App& command, SceneFlags& flags);

// --scene FILE, or one object from --mesh (with --env, --material, --rotate),
// or the built-in default scene. Throws std::invalid_argument on a bad mix.
render::Scene sceneFromFlags(const SceneFlags& flags);

// --background env|black, validated.
bool environmentBackground(const SceneFlags& flags);

// --antialias auto|on|off for a backend: auto is on (the cpu and vulkan
// backends both draw it); a flag outside the three is an error.
bool antialiasFor(const std::string& flag, const std::string& backend);

// --out ends in .exr or .png and its folder exists and is writable: checked
// before any work starts. Throws std::invalid_argument naming the problem.
void checkOutputPath(const SceneFlags& flags);

// --out .exr (and a tonemapped .png beside it) or .png; --exposure, or
// auto exposure (render/exposure_meter.h), through --tone's curve
// (render/tonemap.h). Prints what it wrote.
void writeOutputImages(const SceneFlags& flags, const io::RgbImage& image, const std::vector<std::uint8_t>& objectMask);

}  // namespace haarcast::app
