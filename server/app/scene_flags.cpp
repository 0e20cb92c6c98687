#include "scene_flags.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "haarcast/io/mesh_io.h"
#include "plots.h"

namespace haarcast::app {

namespace fs = std::filesystem;

void addSceneFlags(CLI::App& c, SceneFlags& f) {
  c.add_option("--scene", f.scene, "Scene file (JSON); see docs/scenes.md");
  c.add_option("--env", f.env, "Environment: EXR, HDR or PFM light probe (lat-long or angular)");
  c.add_option("--env-layout", f.layout, "auto|latlong|angular")->capture_default_str();
  c.add_option("--mesh", f.mesh, "OBJ or PLY mesh (centred and scaled to unit radius)");
  c.add_option("--material", f.material, "lambert, phong:EXP, blinn-phong:EXP, ggx:ROUGHNESS or a MERL .binary")
      ->capture_default_str();
  c.add_option("--rotate", f.rotate, "Object rotation X,Y,Z in degrees")->delimiter(',')->expected(3);
  c.add_option("--width", f.width, "Image width")->capture_default_str();
  c.add_option("--height", f.height, "Image height")->capture_default_str();
  c.add_option("--background", f.background, "env|black (black: only the object's pixels are non-zero)")
      ->capture_default_str();
  c.add_option("--out", f.out, "Output .exr (a .png is written beside it) or .png")->capture_default_str();
  c.add_option("--exposure", f.exposure, "PNG exposure in stops (default: log-average luminance → 0.18)");
}

render::Scene sceneFromFlags(const SceneFlags& f) {
  if (!f.scene.empty()) {
    if (!f.mesh.empty() || !f.env.empty()) throw std::invalid_argument("give either --scene or --env/--mesh, not both");
    return render::loadScene(f.scene);
  }
  if (f.mesh.empty()) {
    if (!f.env.empty()) throw std::invalid_argument("--env needs --mesh (or use --scene)");
    return render::defaultScene();
  }
  render::Scene scene = render::defaultScene();
  scene.objects.clear();
  if (!f.env.empty()) scene.environment = render::environmentFromFile(f.env, f.layout);
  auto mesh = std::make_shared<Mesh>(io::loadMesh(f.mesh));
  render::fitToUnitSphere(*mesh);
  render::SceneObject object{fs::path(f.mesh).stem().string(), mesh, render::materialFromSpec(f.material), {}};
  if (!f.rotate.empty()) {
    if (f.rotate.size() != 3) throw std::invalid_argument("--rotate takes X,Y,Z in degrees");
    object.pose.rotateDegrees = {f.rotate[0], f.rotate[1], f.rotate[2]};
  }
  scene.objects.push_back(object);
  scene.camera.eye = {0.0, 0.3, 3.0};
  return scene;
}

bool environmentBackground(const SceneFlags& f) {
  if (f.background != "env" && f.background != "black") {
    throw std::invalid_argument("--background must be env or black (got \"" + f.background + "\")");
  }
  return f.background == "env";
}

void writeOutputImages(const SceneFlags& f, const io::RgbImage& image) {
  const double exposure = f.exposure ? *f.exposure : reinhardKeyExposure(image);
  const fs::path out(f.out);
  const std::string ext = out.extension().string();
  if (ext == ".exr") {
    io::writeExr(out.string(), image);
    fs::path png = out;
    io::writePng(png.replace_extension(".png").string(), image, exposure);
    std::fprintf(stderr, "wrote %s and %s\n", out.c_str(), png.c_str());
  } else if (ext == ".png") {
    io::writePng(out.string(), image, exposure);
    std::fprintf(stderr, "wrote %s\n", out.c_str());
  } else {
    throw std::invalid_argument("--out must end in .exr or .png (got \"" + f.out + "\")");
  }
}

}  // namespace haarcast::app
