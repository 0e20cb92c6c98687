// What `haarcast serve` tells its clients about scenes, materials, probes
// and meshes (serve_catalog.h): no Welcome or SceneInfo field may hold a
// path of the server. A scene file that names its mesh and MERL material by
// absolute paths, served with --materials-dir, and the probes and meshes of
// --data must reach clients as names only; the catalogue lists exactly the
// files it can read, and a mesh's up axis is guessed from its bounds
// (mesh_scene.h).
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

#include "haarcast/io/image.h"
#include "haarcast/net/messages.h"
#include "mesh_scene.h"
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

// A box of extent (x, y, z) as OBJ text, its corner at the origin.
std::string boxObj(double x, double y, double z) {
  std::string obj;
  for (int i = 0; i < 8; ++i) {
    obj += "v " + std::to_string(i & 1 ? x : 0.0) + " " + std::to_string(i & 2 ? y : 0.0) + " " +
           std::to_string(i & 4 ? z : 0.0) + "\n";
  }
  // Two triangles per face, vertices 1-based.
  obj += "f 1 3 2\nf 2 3 4\nf 5 6 7\nf 6 8 7\nf 1 2 5\nf 2 6 5\nf 3 7 4\nf 4 7 8\nf 1 5 3\nf 3 5 7\nf 2 4 6\nf 4 8 6\n";
  return obj;
}

// A --data folder: two probes (a lat-long PFM, an EXR), a Z-up tall box and
// a Y-up box, one MERL table, and files of other kinds that it must ignore.
void writeDataFolder(const std::filesystem::path& root) {
  for (const char* sub : {"probes", "meshes", "brdfs"}) std::filesystem::create_directories(root / sub);
  io::RgbImage sky{16, 8, std::vector<float>(16 * 8 * 3, 0.5f)};
  io::writePfm((root / "probes" / "flat.pfm").string(), sky);
  io::writeExr((root / "probes" / "dusk.exr").string(), sky);
  writeFile(root / "probes" / "README.txt", "not a probe");
  writeFile(root / "meshes" / "statue.obj", boxObj(1.0, 0.8, 3.0));
  writeFile(root / "meshes" / "crate.obj", boxObj(1.0, 1.0, 1.0));
  writeFile(root / "meshes" / "notes.md", "not a mesh");
  writeFile(root / "brdfs" / "gilt-data.binary", constantMerl(0.05));
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
  writeDataFolder(dir / "data");
  const ServeCatalog served = buildServeCatalog(scenes, (dir / "brdfs").string(), (dir / "data").string());

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
  // And a mesh scene of --data under one of its probes.
  net::SessionConfig meshConfig = config;
  v1::SceneChoice choice;
  choice.set_scene("gallery");
  choice.set_probe("dusk");
  choice.set_mesh("statue");
  ASSERT_FALSE(net::applySceneChoice(meshConfig, choice, served.catalog));
  v1::ServerMessage meshInfo;
  ASSERT_TRUE(meshInfo.ParseFromString(net::sceneInfoMessage(meshConfig, served.catalog)));
  EXPECT_EQ(meshInfo.scene_info().probe(), "dusk");
  EXPECT_EQ(meshInfo.scene_info().mesh(), "statue");
  ASSERT_EQ(welcome.welcome().probes_size(), 2);
  ASSERT_EQ(welcome.welcome().meshes_size(), 2);

  const auto& objects = info.scene_info().objects();
  ASSERT_EQ(objects.size(), 3);
  EXPECT_EQ(objects[0].material(), "merl:gilt-test");  // the name a user gave: the file's stem
  EXPECT_EQ(objects[1].material(), "merl:gilt-test");
  EXPECT_EQ(objects[2].material(), "phong:64");
  std::vector<std::pair<std::string, std::string>> strings;
  collectStrings(welcome, "server_message", strings);
  collectStrings(info, "server_message", strings);
  collectStrings(meshInfo, "server_message", strings);
  ASSERT_GT(strings.size(), 20u);
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

TEST(ServeCatalog, DataOffersExactlyItsProbesMeshesAndMaterialsByName) {
  TempDir dir("haarcast-serve-data-");
  writeDataFolder(dir.path());
  const ServeCatalog served = buildServeCatalog({{"default", render::defaultScene()}}, "", dir.path().string());
  const net::Catalog& c = served.catalog;
  EXPECT_EQ(c.probes, (std::vector<std::string>{"dusk", "flat"}));
  EXPECT_EQ(c.meshNames(), (std::vector<std::string>{"crate", "statue"}));
  EXPECT_EQ(c.materials.back(), "merl:gilt-data");
  EXPECT_EQ(c.materials.size(), kBuiltinMaterials.size() + 1);
  EXPECT_EQ(served.probeFiles.at("flat"), (dir / "probes" / "flat.pfm").string());
  // The guess from each box's bounds as its file has them.
  EXPECT_EQ(c.findMesh("statue")->guessedUp, render::UpAxis::Z);
  EXPECT_EQ(c.findMesh("crate")->guessedUp, render::UpAxis::Y);
  // A mesh scene: the mesh and a ground, at the poses the renderer will draw.
  const net::Catalog::SceneEntry& statue = c.findMesh("statue")->upZ;
  EXPECT_EQ(statue.objectNames, (std::vector<std::string>{"statue", "ground"}));
  EXPECT_EQ(statue.defaultMaterials, (std::vector<std::string>{kMeshMaterial, "lambert"}));
  EXPECT_LT(statue.poses[1].translate.y, c.findMesh("statue")->upY.poses[1].translate.y)
      << "stood up along its 3-long side, the statue reaches lower than lying on it";

  // What a config of these names draws: the files behind them.
  net::SessionConfig config;
  config.scene = "default";
  config.probe = "flat";
  config.mesh = "statue";
  config.up = render::UpAxis::Z;
  config.materials = {"merl:gilt-data", "lambert"};
  const render::Scene scene = servedScene({{"default", render::defaultScene()}}, served, config);
  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_EQ(scene.objects[0].material.name, "merl:gilt-data");
  EXPECT_TRUE(scene.objects[1].ground);
  const Bounds b = scene.objects[0].mesh->bounds();
  EXPECT_GT(b.hi.y - b.lo.y, 2.0 * (b.hi.z - b.lo.z)) << "a Z-up statue stands along +Y";
  EXPECT_NEAR(scene.environment.radiance({0.0, 1.0, 0.0}).x, 0.5, 1e-6) << "the probe's light, not the sky's";
  config.probe = "nowhere";
  EXPECT_THROW(servedScene({{"default", render::defaultScene()}}, served, config), std::invalid_argument);
}

TEST(ServeCatalog, TheUpGuessStandsTallZMeshesAndLeavesTheRest) {
  EXPECT_EQ(guessUpAxis(glm::dvec3(1.0, 0.8, 3.0)), render::UpAxis::Z);          // a tall box stored Z-up
  EXPECT_EQ(guessUpAxis(glm::dvec3(930.1, 533.8, 1597.2)), render::UpAxis::Z);   // Lucy
  EXPECT_EQ(guessUpAxis(glm::dvec3(1.0, 3.0, 0.8)), render::UpAxis::Y);          // the same box, Y-up
  EXPECT_EQ(guessUpAxis(glm::dvec3(0.156, 0.154, 0.121)), render::UpAxis::Y);    // the bunny
  EXPECT_EQ(guessUpAxis(glm::dvec3(0.943, 1.690, 1.718)), render::UpAxis::Y);    // Spot: long in Z, tall in Y
  EXPECT_EQ(guessUpAxis(glm::dvec3(6.4, 3.2, 4.0)), render::UpAxis::Y);          // the teapot
  EXPECT_EQ(guessUpAxis(glm::dvec3(1.0, 1.0, 1.0)), render::UpAxis::Y);          // no evidence: haarcast's +Y
}

TEST(ServeCatalog, BadDataIsNamedWithWhatWasExpected) {
  const auto message = [](const std::string& data) {
    try {
      buildServeCatalog({}, "", data);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(message("/nonexistent/haarcast-data"), "--data /nonexistent/haarcast-data is not a folder");
  TempDir empty("haarcast-serve-data-empty-");
  EXPECT_EQ(message(empty.path().string()),
            "--data " + empty.path().string() +
                " has none of the folders it is read for: probes/ (.exr, .hdr, .pic, .rgbe, .pfm), meshes/ (.ply, "
                ".obj), brdfs/ (MERL .binary)");
  TempDir bad("haarcast-serve-data-bad-");
  writeDataFolder(bad.path());
  writeFile(bad / "probes" / "broken.hdr", "not a Radiance file");
  const std::string probe = message(bad.path().string());
  EXPECT_EQ(probe.rfind("--data: probe " + (bad / "probes" / "broken.hdr").string() + " does not load: ", 0), 0u) << probe;
  std::filesystem::remove(bad / "probes" / "broken.hdr");
  writeFile(bad / "meshes" / "statue.ply", "ply\nformat ascii 1.0\nend_header\n");
  const std::string twice = message(bad.path().string());
  EXPECT_NE(twice.find("have one name, \"statue\""), std::string::npos) << twice;
}

}  // namespace
}  // namespace haarcast::app
