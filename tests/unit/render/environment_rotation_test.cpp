// A scene file's "environment": {"rotate": [x, y, z]} (scene.h
// Environment::rotation): the same turn as the wire's light pose, so a scene
// turned in its file renders exactly as the unturned scene asked for that
// light rotation, on the point lights, the map light, the ground's hidden
// sky and the backdrop alike; and its radiance (the Monte Carlo reference's)
// turns with it.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"

namespace haarcast::render {
namespace {

const glm::dvec3 kTurnDegrees(20.0, 50.0, -10.0);

Scene sceneWith(const std::string& name, const std::string& rotate) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << R"({"environment": {"builtin": "suns")" << rotate << R"(},
    "camera": {"eye": [0, 1.2, 3.0], "target": [0, 0, 0], "fov_y": 40},
    "ground": true,
    "objects": [{"name": "ball", "mesh": {"builtin": "sphere"}, "material": "ggx:0.2", "scale": 0.6}]})";
  Scene s = loadScene(path.string());
  std::filesystem::remove(path);
  return s;
}

Frame renderOnce(const Scene& scene, const glm::dmat3& lightRotation) {
  RenderOptions o;
  o.width = 48;
  o.height = 40;
  o.level = 4;
  o.method = RotationMethod::Fused;
  o.environmentBackground = true;
  const std::unique_ptr<Renderer> renderer = makeCpuRenderer(scene, o);
  FrameRequest request;
  request.width = o.width;
  request.height = o.height;
  request.camera = scene.camera;
  request.lightRotation = lightRotation;
  request.exposure.automatic = false;
  return renderer->render(request);
}

std::size_t differingValues(const Frame& a, const Frame& b) {
  EXPECT_EQ(a.image.rgb.size(), b.image.rgb.size());
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.image.rgb.size() && i < b.image.rgb.size(); ++i) n += a.image.rgb[i] != b.image.rgb[i];
  return n;
}

TEST(EnvironmentRotation, ASceneFileTurnsItsEnvironmentAsTheWiresLightPose) {
  const Scene turned = sceneWith("haarcast_env_turned.json", R"(, "rotate": [20, 50, -10])");
  const Scene plain = sceneWith("haarcast_env_plain.json", "");
  Pose pose;
  pose.rotateDegrees = kTurnDegrees;
  const glm::dmat3 turn = pose.rotation();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_DOUBLE_EQ(turned.environment.rotation[c][r], turn[c][r]);

  // The radiance per world direction: what came from d now comes from R·d.
  for (const glm::dvec3 d : {glm::dvec3(0.0, 1.0, 0.0), glm::normalize(glm::dvec3(0.4, 0.5, -0.7))}) {
    const glm::dvec3 a = turned.environment.radiance(turn * d), b = plain.environment.radiance(d);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], 1e-12 * (1.0 + b[c]));
  }

  // The frames: the turned scene as is = the plain scene under the light pose.
  const Frame a = renderOnce(turned, glm::dmat3(1.0));
  const Frame b = renderOnce(plain, turn);
  const Frame unturned = renderOnce(plain, glm::dmat3(1.0));
  EXPECT_EQ(differingValues(a, b), 0u);
  EXPECT_GT(differingValues(a, unturned), a.image.rgb.size() / 4);  // the turn shows
  // A light pose on top composes with the scene's own turn.
  const Frame both = renderOnce(turned, turn);
  const Frame twice = renderOnce(plain, turn * turn);
  EXPECT_EQ(differingValues(both, twice), 0u);
}

TEST(EnvironmentRotation, ABadRotateNamesTheKey) {
  const auto path = std::filesystem::temp_directory_path() / "haarcast_env_bad.json";
  std::ofstream(path) << R"({"environment": {"builtin": "sky", "rotate": [1, 2]}, "objects": []})";
  std::string why = "(loaded)";
  try {
    (void)loadScene(path.string());
  } catch (const std::runtime_error& e) {
    why = e.what();
  }
  std::filesystem::remove(path);
  EXPECT_NE(why.find("environment.rotate"), std::string::npos) << why;
  EXPECT_NE(why.find("three numbers"), std::string::npos) << why;
}

}  // namespace
}  // namespace haarcast::render
