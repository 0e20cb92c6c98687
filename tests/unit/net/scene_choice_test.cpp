// SceneChoice's probe, mesh and up (protocol.h): names the catalogue offers
// or a non-fatal error naming the choices; the up axis guessed unless
// chosen; SceneInfo saying what is in effect; and a renderer per choice
// (rendererKey), so that sessions with different probes or meshes never
// share one.
#include "haarcast/net/protocol.h"

#include <gtest/gtest.h>

namespace haarcast::net {
namespace {

Catalog::SceneEntry entry(std::string name, std::vector<std::string> materials, std::vector<std::string> objects,
                          double groundY) {
  Catalog::SceneEntry e{std::move(name), std::move(materials), render::Camera{}, {}, std::move(objects)};
  e.poses.resize(e.defaultMaterials.size());
  e.poses.back().translate = {0.0, groundY, 0.0};
  return e;
}

// Two scenes, two probes, two meshes: "statue" guessed Z-up, "cow" Y-up.
Catalog dataCatalog() {
  Catalog c;
  c.scenes.push_back(entry("default", {"phong:64", "lambert"}, {"ball", "ring"}, 0.0));
  c.scenes.push_back(entry("other", {"ggx:0.3"}, {"teapot"}, 0.0));
  c.materials = {"lambert", "phong:64", "ggx:0.3"};
  c.backends = {Backend::Cpu};
  c.probes = {"grace", "uffizi"};
  for (const auto& [name, guess] : {std::pair{"statue", render::UpAxis::Z}, {"cow", render::UpAxis::Y}}) {
    Catalog::MeshEntry m{name, guess, entry(name, {"phong:64", "lambert"}, {name, "ground"}, -0.5),
                         entry(name, {"phong:64", "lambert"}, {name, "ground"}, -0.9)};
    c.meshes.push_back(m);
  }
  return c;
}

SessionConfig startConfig(const Catalog& catalog) {
  v1::Hello h;
  h.set_protocol_version(kProtocolVersion);
  h.set_width(64);
  h.set_height(64);
  auto r = configFromHello(h, Limits{}, Defaults{}, catalog);
  EXPECT_TRUE(std::holds_alternative<SessionConfig>(r));
  return std::get<SessionConfig>(r);
}

TEST(SceneChoice, AProbeAndAMeshAreChosenByNameAndTheUpAxisIsGuessed) {
  const Catalog catalog = dataCatalog();
  SessionConfig c = startConfig(catalog);
  v1::SceneChoice choice;
  choice.set_scene("other");
  choice.set_probe("uffizi");
  choice.set_mesh("statue");
  ASSERT_FALSE(applySceneChoice(c, choice, catalog));
  EXPECT_EQ(c.scene, "other");
  EXPECT_EQ(c.probe, "uffizi");
  EXPECT_EQ(c.mesh, "statue");
  EXPECT_EQ(c.up, render::UpAxis::Z);  // the catalogue's guess
  EXPECT_EQ(c.materials, (std::vector<std::string>{"phong:64", "lambert"}));  // the mesh scene's objects

  const v1::SceneInfo info = sceneInfo(c, catalog);
  EXPECT_EQ(info.name(), "other");
  EXPECT_EQ(info.probe(), "uffizi");
  EXPECT_EQ(info.mesh(), "statue");
  EXPECT_EQ(info.up(), "z");
  ASSERT_EQ(info.objects_size(), 2);
  EXPECT_EQ(info.objects(0).name(), "statue");
  EXPECT_EQ(info.objects(1).name(), "ground");
  EXPECT_DOUBLE_EQ(info.objects(1).pose().translate().y(), -0.9);  // the Z-up scene's ground

  // Flipped by the client: the other mesh scene, the materials kept.
  choice.set_up("y");
  (*choice.mutable_object_materials())[0] = "ggx:0.3";
  ASSERT_FALSE(applySceneChoice(c, choice, catalog));
  EXPECT_EQ(c.up, render::UpAxis::Y);
  EXPECT_EQ(c.materials[0], "ggx:0.3");
  EXPECT_DOUBLE_EQ(sceneInfo(c, catalog).objects(1).pose().translate().y(), -0.5);
  EXPECT_EQ(sceneInfo(c, catalog).up(), "y");
  EXPECT_EQ(sceneEntry(c, catalog), &catalog.meshes[0].upY);

  // Back to the scene's own objects and environment: every field is the whole choice.
  v1::SceneChoice plain;
  plain.set_scene("other");
  ASSERT_FALSE(applySceneChoice(c, plain, catalog));
  EXPECT_EQ(c.probe, "");
  EXPECT_EQ(c.mesh, "");
  EXPECT_EQ(c.materials, (std::vector<std::string>{"ggx:0.3"}));
  const v1::SceneInfo back = sceneInfo(c, catalog);
  EXPECT_EQ(back.up(), "");
  EXPECT_EQ(back.objects(0).name(), "teapot");
}

TEST(SceneChoice, UnknownProbesMeshesAndUpAxesAreRefusedNamingTheChoices) {
  const Catalog catalog = dataCatalog();
  SessionConfig c = startConfig(catalog);
  const SessionConfig before = c;
  const auto refused = [&](const std::string& probe, const std::string& mesh, const std::string& up) {
    v1::SceneChoice choice;
    choice.set_probe(probe);
    choice.set_mesh(mesh);
    choice.set_up(up);
    auto e = applySceneChoice(c, choice, catalog);
    EXPECT_TRUE(e.has_value()) << probe << "/" << mesh << "/" << up << " accepted";
    EXPECT_EQ(c.rendererKey(), before.rendererKey()) << "a refused choice changed the config";
    return e.value_or(ProtocolError{});
  };
  const ProtocolError probe = refused("/etc/passwd", "", "");
  EXPECT_EQ(probe.code, v1::ERROR_CODE_UNKNOWN_SCENE);
  EXPECT_FALSE(probe.fatal);
  EXPECT_EQ(probe.message, "unknown probe \"/etc/passwd\" (this server offers grace, uffizi)");
  const ProtocolError mesh = refused("grace", "lucy", "");
  EXPECT_EQ(mesh.code, v1::ERROR_CODE_UNKNOWN_SCENE);
  EXPECT_EQ(mesh.message, "unknown mesh \"lucy\" (this server offers statue, cow)");
  const ProtocolError up = refused("", "cow", "x");
  EXPECT_EQ(up.code, v1::ERROR_CODE_BAD_SETTINGS);
  EXPECT_EQ(up.message, "unknown up \"x\" (valid: y, z)");
  const ProtocolError upAlone = refused("", "", "z");
  EXPECT_EQ(upAlone.code, v1::ERROR_CODE_BAD_SETTINGS);
  EXPECT_NE(upAlone.message.find("applies to a mesh"), std::string::npos) << upAlone.message;

  // A server without --data offers none, and says so.
  Catalog bare = dataCatalog();
  bare.probes.clear();
  bare.meshes.clear();
  SessionConfig d = startConfig(bare);
  v1::SceneChoice choice;
  choice.set_mesh("statue");
  const auto none = applySceneChoice(d, choice, bare);
  ASSERT_TRUE(none);
  EXPECT_EQ(none->message, "unknown mesh \"statue\" (this server offers none)");

  // In a Hello the same refusal ends the session: it has nothing to draw.
  v1::Hello h;
  h.set_protocol_version(kProtocolVersion);
  h.mutable_scene()->set_probe("nowhere");
  const auto hello = configFromHello(h, Limits{}, Defaults{}, catalog);
  ASSERT_TRUE(std::holds_alternative<ProtocolError>(hello));
  EXPECT_TRUE(std::get<ProtocolError>(hello).fatal);
}

TEST(SceneChoice, DifferentProbesMeshesOrUpAxesNeedDifferentRenderers) {
  const Catalog catalog = dataCatalog();
  const auto configWith = [&](const std::string& probe, const std::string& mesh, const std::string& up) {
    SessionConfig c = startConfig(catalog);
    v1::SceneChoice choice;
    choice.set_probe(probe);
    choice.set_mesh(mesh);
    choice.set_up(up);
    EXPECT_FALSE(applySceneChoice(c, choice, catalog));
    return c;
  };
  const SessionConfig grace = configWith("grace", "", ""), uffizi = configWith("uffizi", "", "");
  EXPECT_NE(grace.rendererKey(), uffizi.rendererKey());
  EXPECT_NE(grace.rendererKey(), configWith("", "", "").rendererKey());
  EXPECT_EQ(grace.rendererKey(), configWith("grace", "", "").rendererKey()) << "one choice, one renderer";
  const SessionConfig cow = configWith("grace", "cow", "");
  EXPECT_NE(cow.rendererKey(), grace.rendererKey());
  EXPECT_NE(cow.rendererKey(), configWith("grace", "statue", "").rendererKey());
  EXPECT_NE(cow.rendererKey(), configWith("grace", "cow", "z").rendererKey());
  EXPECT_EQ(cow.rendererKey(), configWith("grace", "cow", "y").rendererKey()) << "the guess, chosen: the same renderer";
}

}  // namespace
}  // namespace haarcast::net
