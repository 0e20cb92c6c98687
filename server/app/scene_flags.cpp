#include "scene_flags.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include <unistd.h>

#include "haarcast/io/mesh_io.h"
#include "haarcast/render/exposure_meter.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/tonemap.h"
#include "mesh_scene.h"

namespace haarcast::app {

namespace fs = std::filesystem;

void addSceneFlags(CLI::App& c, SceneFlags& f) {
  c.add_option("--scene", f.scene, "Scene file (JSON); see docs/scenes.md");
  c.add_option("--env", f.env, "Environment: EXR, HDR or PFM light probe (lat-long or angular)");
  c.add_option("--env-layout", f.layout, "auto|latlong|angular")->capture_default_str();
  c.add_option("--mesh", f.mesh, "OBJ or PLY mesh (centred and scaled to unit radius)");
  c.add_option("--material", f.material,
               std::string("With --mesh: lambert, phong:EXP, blinn-phong:EXP, ggx:ROUGHNESS or a MERL .binary (default ") +
                   kMeshMaterial + ")");
  c.add_option("--up", f.up, "With --mesh: its up axis as the file has it, y|z (z: turned to stand along +Y; "
                             "scene files: \"up\" per object)");
  c.add_option("--rotate", f.rotate, "Object rotation X,Y,Z in degrees")->delimiter(',')->expected(3);
  c.add_option("--width", f.width, "Image width")->capture_default_str();
  c.add_option("--height", f.height, "Image height")->capture_default_str();
  c.add_option("--background", f.background, "env|black (black: only the object's pixels are non-zero)")
      ->capture_default_str();
  c.add_option("--out", f.out, "Output .exr (a .png is written beside it) or .png")->capture_default_str();
  c.add_option("--exposure", f.exposure,
               "PNG exposure in stops (default: auto, the whole frame's log-average luminance → 0.18, objects "
               "weighted 4×, held down so the brightest 1% does not clip)");
  std::vector<std::string> tones;
  for (const render::ToneCurve t : render::kToneCurves) tones.emplace_back(render::toneCurveName(t));
  c.add_option("--tone", f.tone, "PNG tone curve: reinhard|aces|agx (docs/design.md, \"Display\")")
      ->check(CLI::IsMember(tones))
      ->capture_default_str();
  c.add_flag("--ground", f.ground, "With --mesh: stand it on a ground that takes its shadows (scene files: the \"ground\" key)");
  addSceneLimitFlags(c, f.limits);
}

void addSceneLimitFlags(CLI::App& c, render::SceneLimits& limits) {
  c.add_option("--max-scene-objects", limits.maxObjects, "Most objects a scene may hold")->capture_default_str();
  c.add_option("--max-scene-triangles", limits.maxTriangles, "Most triangles of all a scene's objects together")
      ->capture_default_str();
  c.add_option_function<std::size_t>(
       "--max-visibility-mb", [&limits](std::size_t mb) { limits.maxVisibilityBytes = mb << 20; },
       "Most per-vertex visibility a scene may hold, MB (default " + std::to_string(limits.maxVisibilityBytes >> 20) + ")")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1} << 24));
}

namespace {
render::UpAxis parseUp(const std::string& text) {
  try {
    return render::parseUpAxis(text);
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument("--up " + text + " is not an up axis (valid: y, z)");
  }
}
}  // namespace

render::Scene sceneFromFlags(const SceneFlags& f) {
  if (!f.scene.empty()) {
    if (!f.mesh.empty() || !f.env.empty()) throw std::invalid_argument("give either --scene or --env/--mesh, not both");
    if (f.ground) throw std::invalid_argument("--ground applies to --mesh (a scene file says \"ground\": true)");
    if (!f.up.empty()) throw std::invalid_argument("--up applies to --mesh (a scene file says \"up\": \"z\" per object)");
    return render::loadScene(f.scene, f.limits);
  }
  if (f.mesh.empty()) {
    // The built-in scene's objects have their own materials and poses.
    if (!f.env.empty()) throw std::invalid_argument("--env needs --mesh (or use --scene)");
    if (f.ground) throw std::invalid_argument("--ground applies to --mesh (the default scene has its own ground)");
    if (!f.material.empty()) throw std::invalid_argument("--material applies to --mesh (the default scene's objects have their own)");
    if (!f.rotate.empty()) throw std::invalid_argument("--rotate applies to --mesh (the default scene's objects have their own poses)");
    if (!f.up.empty()) throw std::invalid_argument("--up applies to --mesh (the default scene's objects stand along +Y)");
    return render::defaultScene();
  }
  // Before any file is read: a bad --up fails at once.
  const render::UpAxis up = f.up.empty() ? render::UpAxis::Y : parseUp(f.up);
  render::Pose pose;
  if (!f.rotate.empty()) {
    if (f.rotate.size() != 3) throw std::invalid_argument("--rotate takes X,Y,Z in degrees");
    pose.rotateDegrees = {f.rotate[0], f.rotate[1], f.rotate[2]};
  }
  const render::Material material = render::materialFromSpec(f.material.empty() ? kMeshMaterial : f.material);
  render::Scene scene = meshScene(io::loadMesh(f.mesh), fs::path(f.mesh).stem().string(), up, material, pose, f.ground);
  if (!f.env.empty()) scene.environment = render::environmentFromFile(f.env, f.layout);
  return scene;
}

bool environmentBackground(const SceneFlags& f) {
  if (f.background != "env" && f.background != "black") {
    throw std::invalid_argument("--background must be env or black (got \"" + f.background + "\")");
  }
  return f.background == "env";
}

bool antialiasFor(const std::string& flag, [[maybe_unused]] const std::string& backend) {
  if (flag != "auto" && flag != "on" && flag != "off") {
    throw std::invalid_argument("--antialias must be auto, on or off (got \"" + flag + "\")");
  }
  // Both backends draw it (the edge rule of core/shared_layout.h), so auto is on.
  return flag != "off";
}

void checkOutputPath(const SceneFlags& f) {
  const fs::path out(f.out);
  const std::string ext = out.extension().string();
  if (ext != ".exr" && ext != ".png") {
    throw std::invalid_argument("--out must end in .exr or .png (got \"" + f.out + "\")");
  }
  // Before the work starts, not after a render of minutes.
  const fs::path dir = out.has_parent_path() ? out.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw std::invalid_argument("--out " + f.out + ": the folder " + dir.string() + " does not exist");
  }
  if (::access(dir.c_str(), W_OK) != 0) {
    throw std::invalid_argument("--out " + f.out + ": the folder " + dir.string() + " is not writable");
  }
}

void writeOutputImages(const SceneFlags& f, const io::RgbImage& image, const std::vector<std::uint8_t>& objectMask) {
  checkOutputPath(f);
  // The service's display transform (render/tonemap.h); auto exposure
  // (render/exposure_meter.h) unless --exposure fixes it.
  const render::ToneCurve tone = render::parseToneCurve(f.tone).value_or(render::ToneCurve::Reinhard);  // checked by CLI11
  const double exposure = f.exposure ? *f.exposure : render::meterExposure(image, objectMask, {}, tone).stops;
  const std::vector<std::uint8_t> rgba8 = render::tonemapRgba8(image, exposure, tone);
  const fs::path out(f.out);
  if (out.extension() == ".exr") {
    io::writeExr(out.string(), image);
    fs::path png = out;
    io::writePngRgba8(png.replace_extension(".png").string(), rgba8, image.width, image.height);
    std::fprintf(stderr, "wrote %s and %s (exposure %+.2f stops)\n", out.c_str(), png.c_str(), exposure);
  } else {
    io::writePngRgba8(out.string(), rgba8, image.width, image.height);
    std::fprintf(stderr, "wrote %s (exposure %+.2f stops)\n", out.c_str(), exposure);
  }
}

}  // namespace haarcast::app
