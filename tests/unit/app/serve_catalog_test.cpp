// What `haarcast serve` tells its clients about scenes and materials
// (serve_catalog.h): no Welcome or SceneInfo field may hold a path of the
// server. A scene file that names its mesh and MERL material by absolute
// paths, served with --materials-dir, must reach clients as names only.
#include "serve_catalog.h"

#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <google/protobuf/descriptor.h>
#include <google/protobuf/message.h>
#include <gtest/gtest.h>

#include "haarcast/net/messages.h"
#include "../test_files.h"

namespace haarcast::app {
namespace {

using haarcast::testing::TempDir;
using haarcast::testing::writeFile;

// A MERL file (int32 dims 90, 90, 180, then three channels of doubles) with
// one value everywhere: any valid table will do, only its name matters here.
std::string constantMerl(double value) {
  static_assert(std::endian::native == std::endian::little, "the test writes host-order bytes");
  const std::int32_t dims[3] = {90, 90, 180};
  const std::size_t cells = 90u * 90u * 180u;
  std::string bytes(12 + 3 * cells * 8, '\0');
  std::memcpy(bytes.data(), dims, 12);
  for (std::size_t i = 0; i < 3 * cells; ++i) std::memcpy(bytes.data() + 12 + 8 * i, &value, 8);
  return bytes;
}

// Every string (and bytes) field of a message and its sub-messages, with
// the field's path: "welcome.scene_info.objects[0].material".
void collectStrings(const google::protobuf::Message& m, const std::string& where,
                    std::vector<std::pair<std::string, std::string>>& out) {
  using google::protobuf::FieldDescriptor;
  const auto* d = m.GetDescriptor();
  const auto* r = m.GetReflection();
  for (int i = 0; i < d->field_count(); ++i) {
    const FieldDescriptor* f = d->field(i);
    const std::string name = where + "." + f->name();
    if (f->is_repeated()) {
      for (int k = 0; k < r->FieldSize(m, f); ++k) {
        const std::string item = name + "[" + std::to_string(k) + "]";
        if (f->cpp_type() == FieldDescriptor::CPPTYPE_STRING) out.emplace_back(item, r->GetRepeatedString(m, f, k));
        if (f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE) collectStrings(r->GetRepeatedMessage(m, f, k), item, out);
      }
    } else if (f->cpp_type() == FieldDescriptor::CPPTYPE_STRING) {
      out.emplace_back(name, r->GetString(m, f));
    } else if (f->cpp_type() == FieldDescriptor::CPPTYPE_MESSAGE && r->HasField(m, f)) {
      collectStrings(r->GetMessage(m, f), name, out);
    }
  }
}

TEST(ServeCatalog, NoWelcomeOrSceneInfoFieldHoldsAPathOfTheServer) {
  TempDir dir("haarcast-serve-catalog-");
  std::filesystem::create_directories(dir / "brdfs");
  const std::string merl = writeFile(dir / "brdfs" / "gilt-test.binary", constantMerl(0.05));
  const std::string scenePath = (dir / "gallery.json").string();
  // One object by an absolute path, one relative to the scene's folder.
  std::ofstream(scenePath) << R"({"objects": [
      {"name": "statue", "mesh": {"builtin": "sphere"}, "material": ")" << merl << R"("},
      {"name": "plinth", "mesh": {"builtin": "box"}, "material": "brdfs/gilt-test.binary"},
      {"name": "ball", "mesh": {"builtin": "sphere"}, "material": "phong:64"}]})";
  const std::vector<ServedScene> scenes = {{"default", render::defaultScene()},
                                           {"gallery", render::loadScene(scenePath)}};
  const ServeCatalog served = buildServeCatalog(scenes, (dir / "brdfs").string());

  // The files stay on the server's side, under the names clients see.
  ASSERT_EQ(served.materialFiles.count("merl:gilt-test"), 1u);
  EXPECT_EQ(served.materialFiles.at("merl:gilt-test"), merl);

  net::SessionConfig config;
  config.width = config.height = 64;
  config.scene = "gallery";
  config.materials = served.catalog.findScene("gallery")->defaultMaterials;
  v1::ServerMessage welcome, info;
  ASSERT_TRUE(welcome.ParseFromString(net::welcomeMessage(config, served.catalog, net::Limits{}, {"s1", 3, "cpu", {}, "host"})));
  ASSERT_TRUE(info.ParseFromString(net::sceneInfoMessage(config, served.catalog)));

  const auto& objects = info.scene_info().objects();
  ASSERT_EQ(objects.size(), 3);
  EXPECT_EQ(objects[0].material(), "merl:gilt-test");  // the name a user gave: the file's stem
  EXPECT_EQ(objects[1].material(), "merl:gilt-test");
  EXPECT_EQ(objects[2].material(), "phong:64");
  std::vector<std::pair<std::string, std::string>> strings;
  collectStrings(welcome, "server_message", strings);
  collectStrings(info, "server_message", strings);
  ASSERT_GT(strings.size(), 10u);
  for (const auto& [field, value] : strings) {
    EXPECT_EQ(value.find(dir.path().string()), std::string::npos) << field << " = \"" << value << "\"";
    EXPECT_EQ(value.find_first_of("/\\"), std::string::npos) << field << " = \"" << value << "\" looks like a path";
  }
}

TEST(ServeCatalog, AMaterialsDirThatIsNotAFolderIsNamed) {
  try {
    buildServeCatalog({}, "/nonexistent/haarcast-brdfs");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "--materials-dir /nonexistent/haarcast-brdfs is not a folder");
  }
}

}  // namespace
}  // namespace haarcast::app
