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
