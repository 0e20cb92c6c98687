// Scene files that are not scenes: each is refused with a runtime_error that
// names the file and what was wrong, never an exception of the JSON library
// (which the server and the fuzz target would not expect).
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

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
