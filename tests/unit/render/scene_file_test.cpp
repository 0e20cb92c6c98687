// Scene files that are not scenes: each is refused with a runtime_error that
// names the file and what was wrong, never an exception of the JSON library
// (which the server and the fuzz target would not expect).
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <future>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"

namespace haarcast::render {
namespace {

std::string refusal(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  try {
    (void)loadScene(path.string());
  } catch (const std::runtime_error& e) {
    std::filesystem::remove(path);
    return e.what();
  }
  std::filesystem::remove(path);
  return "(loaded)";
}

TEST(SceneFile, ANumberNoDoubleHoldsIsInvalidJson) {
  // nlohmann throws out_of_range, not parse_error, for this (found by fuzz_scene).
  const std::string why = refusal("haarcast_scene_huge.json", R"({"environment": {"builtin": 6666666E66666}})");
  EXPECT_NE(why.find("haarcast_scene_huge.json: not valid JSON"), std::string::npos) << why;
}

TEST(SceneFile, AValueOfTheWrongTypeNamesTheFile) {
  const std::string why = refusal("haarcast_scene_type.json", R"({"camera": {"fov_y": "wide"}})");
  EXPECT_NE(why.find("haarcast_scene_type.json: "), std::string::npos) << why;
  EXPECT_EQ(why.find("(loaded)"), std::string::npos);
}

TEST(SceneFile, BrokenJsonIsInvalidJson) {
  const std::string why = refusal("haarcast_scene_broken.json", R"({"camera": )");
  EXPECT_NE(why.find("not valid JSON"), std::string::npos) << why;
}

TEST(SceneFile, TheSunsSkyIsBuiltInAndAnUnknownOneNamesTheChoices) {
  const auto path = std::filesystem::temp_directory_path() / "haarcast_scene_suns.json";
  std::ofstream(path) << R"({"environment": {"builtin": "suns"}, "objects": [{"mesh": {"builtin": "box"}, "material": "lambert"}]})";
  const Scene s = loadScene(path.string());
  std::filesystem::remove(path);
  EXPECT_EQ(s.environment.name, "builtin suns");
  EXPECT_GT(s.environment.radiance({0.0, 1.0, 0.0}).z, 0.0);
  const std::string why = refusal("haarcast_scene_moon.json", R"({"environment": {"builtin": "moon"}, "objects": []})");
  EXPECT_NE(why.find(R"("sky"|"suns")"), std::string::npos) << why;
}

}  // namespace
}  // namespace haarcast::render

namespace haarcast::render {
namespace {

// A scene over the operator's limits is refused naming the limit and the
// count, before its meshes are read (objects) or anything is computed.
TEST(SceneLimits, RefusalsNameTheLimitAndTheCount) {
  std::string objects = "[";
  for (int k = 0; k < 70; ++k) objects += std::string(k ? "," : "") + R"({"mesh": "nowhere.ply", "material": "lambert"})";
  objects += "]";
  const std::string many = refusal("many.json", R"({"objects": )" + objects + "}");
  EXPECT_NE(many.find("70 objects"), std::string::npos) << many;
  EXPECT_NE(many.find("limit of 64"), std::string::npos) << many;
  EXPECT_EQ(many.find("nowhere.ply"), std::string::npos) << "no mesh is read before the count is checked: " << many;

  Scene scene = defaultScene();
  RenderOptions options;
  options.level = 4;
  options.sceneLimits.maxTriangles = 100;
  try {
    (void)prepareScene(scene, options);
    ADD_FAILURE() << "a scene over the triangle limit was prepared";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("over the limit of 100"), std::string::npos) << e.what();
  }
  options.sceneLimits = {};
  options.sceneLimits.maxVisibilityBytes = 1000;
  EXPECT_THROW((void)prepareScene(scene, options), std::invalid_argument);
}

TEST(SceneFile, GroundKeyIsCheckedAndAddsAGround) {
  EXPECT_NE(refusal("g1.json", R"({"objects": [{"mesh": {"builtin": "sphere"}, "material": "lambert"}], "ground": 3})")
                .find("ground"),
            std::string::npos);
  EXPECT_NE(refusal("g2.json", R"({"objects": [{"mesh": {"builtin": "sphere"}, "material": "lambert"}], "ground": {"colour": 1}})")
                .find("unknown key \"colour\""),
            std::string::npos);
  EXPECT_NE(refusal("g3.json", R"({"objects": [{"mesh": {"builtin": "sphere"}, "material": "lambert"}], "ground": {"albedo": 2}})")
                .find("albedo"),
            std::string::npos);
  const auto path = std::filesystem::temp_directory_path() / "g4.json";
  std::ofstream(path) << R"({"objects": [{"mesh": {"builtin": "sphere"}, "material": "lambert"}], "ground": {"albedo": 0.3}})";
  const Scene s = loadScene(path.string());
  std::filesystem::remove(path);
  ASSERT_EQ(s.objects.size(), 2u);
  EXPECT_TRUE(s.objects[1].ground);
  EXPECT_DOUBLE_EQ(s.objects[1].groundAlbedo.x, 0.3);
}

TEST(SceneFile, AFifoOrADirectoryIsRefusedBeforeItIsOpened) {
  const auto dir = std::filesystem::temp_directory_path() / ("haarcast_scene_fifo_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto fifo = dir / "scene.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // Opening a FIFO blocks until a writer comes: the check must come first.
  // Should it not, a writer is opened after 5 s so that the test fails
  // instead of hanging.
  auto error = std::async(std::launch::async, [&] {
    try {
      loadScene(fifo.string());
      return std::string("a FIFO loaded as a scene");
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
  });
  if (error.wait_for(std::chrono::seconds(5)) != std::future_status::ready) {
    const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
  }
  EXPECT_EQ(error.get(), fifo.string() + ": cannot read scene file: is a FIFO (named pipe), not a regular file");
  try {
    loadScene(dir.string());
    ADD_FAILURE() << "a directory loaded as a scene";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace haarcast::render

namespace haarcast::render {
namespace {

// A Z-up mesh (a post 4 tall along +Z, 1 × 1 across, with a tip leaning to
// +X at its top, as Lucy and many scans are stored): "up": "z" stands it
// along +Y, its top still leaning to +X; without it, it lies along Z.
TEST(SceneFile, AZUpMeshStandsAlongYWithUpZ) {
  const auto dir = std::filesystem::temp_directory_path() / "haarcast_scene_up";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "post.obj") << "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\n"
                                     "v -0.5 -0.5 4\nv 0.5 -0.5 4\nv 0.5 0.5 4\nv -0.5 0.5 4\nv 1.5 0 4\n"
                                     "f 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n"
                                     "f 5 6 9\nf 6 7 9\nf 7 8 9\nf 8 5 9\nf 1 3 2\nf 1 4 3\n";
  const auto load = [&](const std::string& up) {
    std::ofstream(dir / "scene.json") << R"({"objects": [{"mesh": "post.obj", "material": "lambert", "fit": false)"
                                      << (up.empty() ? "" : R"(, "up": ")" + up + "\"") << "}]}";
    return loadScene((dir / "scene.json").string());
  };
  const auto extent = [](const Scene& s) {
    const Bounds b = s.objects[0].mesh->bounds();
    return b.hi - b.lo;
  };
  const Scene lying = load("");
  EXPECT_NEAR(extent(lying).z, 4.0, 1e-6);
  EXPECT_NEAR(extent(lying).y, 1.0, 1e-6);
  const Scene standing = load("z");
  EXPECT_NEAR(extent(standing).y, 4.0, 1e-6) << "stands along +Y";
  EXPECT_NEAR(extent(standing).z, 1.0, 1e-6);
  const Mesh& m = *standing.objects[0].mesh;
  // The tip (vertex 9, (1.5, 0, 4)) is at the top, still to +X: a turn, not a mirror.
  EXPECT_NEAR(m.positions[8].x, 1.5f, 1e-6);
  EXPECT_NEAR(m.positions[8].y, 4.0f, 1e-6);
  EXPECT_NEAR(m.positions[8].z, 0.0f, 1e-6);
  // Normals turn with it: the file's +Z-facing top faces now face up.
  const Mesh& flat = *lying.objects[0].mesh;
  for (std::size_t v = 0; v < m.normals.size(); ++v) {
    EXPECT_NEAR(m.normals[v].y, flat.normals[v].z, 1e-6) << v;
    EXPECT_NEAR(m.normals[v].z, -flat.normals[v].y, 1e-6) << v;
  }
  EXPECT_EQ(load("Z").objects[0].mesh->bounds().hi.y, standing.objects[0].mesh->bounds().hi.y);
  // A bad value names the key and the choices.
  std::ofstream(dir / "bad.json") << R"({"objects": [{"mesh": "post.obj", "material": "lambert", "up": "x"}]})";
  try {
    (void)loadScene((dir / "bad.json").string());
    ADD_FAILURE() << "\"up\": \"x\" was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("objects[0].up: up axis \"x\" is not one of y, z"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace haarcast::render
