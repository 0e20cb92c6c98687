#include "haarcast/net/protocol.h"
#include "haarcast/net/messages.h"

#include <gtest/gtest.h>

namespace haarcast::net {
namespace {

Catalog testCatalog() {
  Catalog c;
  c.scenes.push_back({"default", {"phong:64", "lambert"}, render::Camera{}, {render::Pose{}, render::Pose{}}, {"ball", "ring"}});
  c.scenes.push_back({"other", {"ggx:0.3"}, render::Camera{}, {render::Pose{}}, {"teapot"}});
  c.materials = {"lambert", "phong:64", "ggx:0.3", "merl:steel"};
  c.backends = {Backend::Cpu};
  return c;
}

v1::Hello goodHello() {
  v1::Hello h;
  h.set_protocol_version(kProtocolVersion);
  h.set_width(64);
  h.set_height(32);
  h.set_encoding(v1::ENCODING_PNG);
  h.set_fps_cap(10);
  return h;
}

ProtocolError helloError(const v1::Hello& h, const Limits& limits = {}) {
  auto r = configFromHello(h, limits, Defaults{}, testCatalog());
  EXPECT_TRUE(std::holds_alternative<ProtocolError>(r)) << "accepted";
  return std::holds_alternative<ProtocolError>(r) ? std::get<ProtocolError>(r) : ProtocolError{};
}

TEST(Protocol, ParsesAClientMessage) {
  v1::ClientMessage m;
  m.mutable_ping()->set_nonce(42);
  const auto r = parseClientMessage(m.SerializeAsString());
  ASSERT_TRUE(std::holds_alternative<v1::ClientMessage>(r));
  EXPECT_EQ(std::get<v1::ClientMessage>(r).ping().nonce(), 42u);
}

TEST(Protocol, GarbageTruncatedEmptyAndUnknownAreBadMessages) {
  const auto garbage = parseClientMessage(std::string("\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff\xff", 11));
  ASSERT_TRUE(std::holds_alternative<ProtocolError>(garbage));
  EXPECT_EQ(std::get<ProtocolError>(garbage).code, v1::ERROR_CODE_BAD_MESSAGE);

  v1::ClientMessage hello;
  *hello.mutable_hello() = goodHello();
  hello.mutable_hello()->set_client_name("a name long enough to be cut in the middle of the string");
  const std::string bytes = hello.SerializeAsString();
  const auto truncated = parseClientMessage(std::string_view(bytes).substr(0, bytes.size() - 10));
  ASSERT_TRUE(std::holds_alternative<ProtocolError>(truncated));
  EXPECT_NE(std::get<ProtocolError>(truncated).message.find("do not parse"), std::string::npos);

  const auto empty = parseClientMessage("");
  ASSERT_TRUE(std::holds_alternative<ProtocolError>(empty));
  EXPECT_NE(std::get<ProtocolError>(empty).message.find("empty"), std::string::npos);

  // Field 99, varint 1: a message type from a newer client.
  const auto unknown = parseClientMessage(std::string("\x98\x06\x01", 3));
  ASSERT_TRUE(std::holds_alternative<ProtocolError>(unknown));
  EXPECT_NE(std::get<ProtocolError>(unknown).message.find("field 99"), std::string::npos)
      << std::get<ProtocolError>(unknown).message;
  EXPECT_FALSE(std::get<ProtocolError>(unknown).fatal);
}

TEST(Protocol, HelloGivesTheConfig) {
  Limits limits;
  limits.maxFps = 25;
  auto h = goodHello();
  h.set_fps_cap(100);
  h.mutable_scene()->set_scene("default");
  (*h.mutable_scene()->mutable_object_materials())[1] = "merl:steel";
  h.mutable_settings()->set_level(3);
  h.mutable_settings()->set_method(v1::ROTATION_METHOD_SPATIAL);
  const auto r = configFromHello(h, limits, Defaults{}, testCatalog());
  ASSERT_TRUE(std::holds_alternative<SessionConfig>(r)) << std::get<ProtocolError>(r).message;
  const auto& c = std::get<SessionConfig>(r);
  EXPECT_EQ(c.width, 64);
  EXPECT_EQ(c.height, 32);
  EXPECT_EQ(c.encoding, FrameEncoding::Png);
  EXPECT_EQ(c.fps, 25.0);  // capped by the server
  EXPECT_EQ(c.level, 3);
  EXPECT_EQ(c.method, RotationMethod::Spatial);
  EXPECT_EQ(c.materials, (std::vector<std::string>{"phong:64", "merl:steel"}));
  // Same renderer iff scene, materials, level, method, backend agree.
  SessionConfig other = c;
  other.width = 128;
  other.lightCoefficients = 7;
  EXPECT_EQ(other.rendererKey(), c.rendererKey());
  other.level = 4;
  EXPECT_NE(other.rendererKey(), c.rendererKey());
}

TEST(Protocol, EveryMethodCrossesTheWireAndBack) {
  // Each per-pixel method a renderer takes has its wire value, and a Hello
  // asking for it gets it; the error for an unknown one lists them all.
  for (const RotationMethod m : kAllPixelMethods) {
    const v1::RotationMethod wire = toWire(m);
    EXPECT_NE(wire, v1::ROTATION_METHOD_UNSPECIFIED) << methodName(m);
    auto h = goodHello();
    h.mutable_settings()->set_method(wire);
    const auto r = configFromHello(h, Limits{}, Defaults{}, testCatalog());
    ASSERT_TRUE(std::holds_alternative<SessionConfig>(r)) << std::get<ProtocolError>(r).message;
    EXPECT_EQ(std::get<SessionConfig>(r).method, m) << methodName(m);
  }
  EXPECT_EQ(toWire(RotationMethod::Splitsum), v1::ROTATION_METHOD_SPLITSUM);
  auto h = goodHello();
  h.mutable_settings()->set_method(static_cast<v1::RotationMethod>(42));
  EXPECT_NE(helloError(h).message.find("ROTATION_METHOD_SPLITSUM = 6"), std::string::npos) << helloError(h).message;
}

TEST(Protocol, BadHellosNameWhatIsWrong) {
  auto h = goodHello();
  h.set_protocol_version(2);
  EXPECT_EQ(helloError(h).code, v1::ERROR_CODE_UNSUPPORTED_VERSION);

  h = goodHello();
  h.set_width(100000);
  h.set_height(100000);
  auto e = helloError(h);
  EXPECT_EQ(e.code, v1::ERROR_CODE_BAD_RESOLUTION);
  EXPECT_NE(e.message.find("100000x100000"), std::string::npos) << e.message;
  EXPECT_TRUE(e.fatal);

  h = goodHello();
  h.set_width(0);
  EXPECT_EQ(helloError(h).code, v1::ERROR_CODE_BAD_RESOLUTION);

  // Within the width and height limits but over the per-session pixel
  // budget (--max-session-pixels): refused at the Hello, not frame by frame.
  Limits budget;
  budget.maxPixels = 512 * 512;
  h = goodHello();
  h.set_width(1024);
  h.set_height(512);
  e = helloError(h, budget);
  EXPECT_EQ(e.code, v1::ERROR_CODE_BAD_RESOLUTION);
  EXPECT_NE(e.message.find("524288 pixels, over the server's 262144 per session"), std::string::npos) << e.message;
  h.set_width(512);
  EXPECT_TRUE(std::holds_alternative<SessionConfig>(configFromHello(h, budget, Defaults{}, testCatalog())));
  EXPECT_EQ(limitsToWire(budget).max_pixels(), 262144u);

  h = goodHello();
  h.set_fps_cap(-1);
  EXPECT_EQ(helloError(h).code, v1::ERROR_CODE_BAD_SETTINGS);
  h.set_fps_cap(std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(helloError(h).code, v1::ERROR_CODE_BAD_SETTINGS);

  h = goodHello();
  h.set_jpeg_quality(101);
  EXPECT_EQ(helloError(h).code, v1::ERROR_CODE_BAD_SETTINGS);

  h = goodHello();
  h.set_encoding(static_cast<v1::Encoding>(77));
  EXPECT_EQ(helloError(h).code, v1::ERROR_CODE_BAD_SETTINGS);

  h = goodHello();
  h.mutable_scene()->set_scene("nope");
  e = helloError(h);
  EXPECT_EQ(e.code, v1::ERROR_CODE_UNKNOWN_SCENE);
  EXPECT_NE(e.message.find("offers default, other"), std::string::npos) << e.message;

  h = goodHello();
  (*h.mutable_scene()->mutable_object_materials())[0] = "/etc/passwd";
  e = helloError(h);
  EXPECT_EQ(e.code, v1::ERROR_CODE_UNKNOWN_MATERIAL);
  EXPECT_NE(e.message.find("/etc/passwd"), std::string::npos);
  EXPECT_NE(e.message.find("offers lambert, phong:64, ggx:0.3, merl:steel"), std::string::npos) << e.message;

  h = goodHello();
  (*h.mutable_scene()->mutable_object_materials())[5] = "lambert";
  EXPECT_EQ(helloError(h).code, v1::ERROR_CODE_UNKNOWN_MATERIAL);

  h = goodHello();
  h.mutable_settings()->set_level(9);
  EXPECT_EQ(helloError(h).code, v1::ERROR_CODE_BAD_SETTINGS);

  h = goodHello();
  h.mutable_settings()->set_backend(v1::BACKEND_VULKAN);  // not in this catalogue
  e = helloError(h);
  EXPECT_EQ(e.code, v1::ERROR_CODE_BAD_SETTINGS);
  EXPECT_NE(e.message.find("vulkan"), std::string::npos);
  EXPECT_NE(e.message.find("enables cpu"), std::string::npos) << e.message;

  h = goodHello();
  h.mutable_settings()->set_method(static_cast<v1::RotationMethod>(42));
  e = helloError(h);
  EXPECT_EQ(e.code, v1::ERROR_CODE_BAD_SETTINGS);
  EXPECT_NE(e.message.find("ROTATION_METHOD_FUSED = 5"), std::string::npos) << e.message;

  h = goodHello();
  h.mutable_settings()->set_exposure_mode(v1::EXPOSURE_MODE_FIXED);
  h.mutable_settings()->set_exposure_stops(40.0);
  e = helloError(h);
  EXPECT_EQ(e.code, v1::ERROR_CODE_BAD_SETTINGS);
  EXPECT_NE(e.message.find("exposure_stops"), std::string::npos) << e.message;
}

// Exposure: auto unless a Hello or later settings fix it; a settings message
// that leaves the mode unset keeps it; the request carries it.
TEST(Protocol, ExposureModes) {
  auto c = std::get<SessionConfig>(configFromHello(goodHello(), Limits{}, Defaults{}, testCatalog()));
  EXPECT_TRUE(c.autoExposure);
  EXPECT_TRUE(frameRequest(initialPose(render::Camera{}, {}), c).exposure.automatic);
  v1::RenderSettings s;
  s.set_exposure_mode(v1::EXPOSURE_MODE_FIXED);
  s.set_exposure_stops(-2.5);
  ASSERT_FALSE(applySettings(c, s, Limits{}, testCatalog()));
  EXPECT_FALSE(c.autoExposure);
  const render::FrameRequest r = frameRequest(initialPose(render::Camera{}, {}), c);
  EXPECT_FALSE(r.exposure.automatic);
  EXPECT_EQ(r.exposure.stops, -2.5);
  EXPECT_EQ(settingsToWire(c).exposure_mode(), v1::EXPOSURE_MODE_FIXED);
  v1::RenderSettings levelOnly;
  levelOnly.set_level(3);
  ASSERT_FALSE(applySettings(c, levelOnly, Limits{}, testCatalog()));
  EXPECT_FALSE(c.autoExposure);
  v1::RenderSettings automatic;
  automatic.set_exposure_mode(v1::EXPOSURE_MODE_AUTO);
  ASSERT_FALSE(applySettings(c, automatic, Limits{}, testCatalog()));
  EXPECT_TRUE(c.autoExposure);
}

// Tone curve: Reinhard unless a Hello or later settings choose another; a
// settings message that leaves it unset keeps it; the request carries it; a
// value outside the enum is refused naming the valid ones.
TEST(Protocol, ToneCurves) {
  v1::Hello hello = goodHello();
  auto c = std::get<SessionConfig>(configFromHello(hello, Limits{}, Defaults{}, testCatalog()));
  EXPECT_EQ(c.tone, render::ToneCurve::Reinhard);  // an old client's session: as before
  EXPECT_EQ(settingsToWire(c).tone_curve(), v1::TONE_CURVE_REINHARD);
  hello.mutable_settings()->set_tone_curve(v1::TONE_CURVE_AGX);
  c = std::get<SessionConfig>(configFromHello(hello, Limits{}, Defaults{}, testCatalog()));
  EXPECT_EQ(c.tone, render::ToneCurve::Agx);
  v1::RenderSettings s;
  s.set_tone_curve(v1::TONE_CURVE_ACES);
  ASSERT_FALSE(applySettings(c, s, Limits{}, testCatalog()));
  EXPECT_EQ(c.tone, render::ToneCurve::Aces);
  EXPECT_EQ(frameRequest(initialPose(render::Camera{}, {}), c).tone, render::ToneCurve::Aces);
  EXPECT_EQ(settingsToWire(c).tone_curve(), v1::TONE_CURVE_ACES);
  v1::RenderSettings levelOnly;
  levelOnly.set_level(3);
  ASSERT_FALSE(applySettings(c, levelOnly, Limits{}, testCatalog()));
  EXPECT_EQ(c.tone, render::ToneCurve::Aces);
  v1::RenderSettings bad;
  bad.set_tone_curve(static_cast<v1::ToneCurve>(9));
  const auto e = applySettings(c, bad, Limits{}, testCatalog());
  ASSERT_TRUE(e);
  EXPECT_EQ(e->code, v1::ERROR_CODE_BAD_SETTINGS);
  EXPECT_NE(e->message.find("tone_curve 9"), std::string::npos) << e->message;
  EXPECT_NE(e->message.find("REINHARD, ACES, AGX"), std::string::npos) << e->message;
  EXPECT_EQ(c.tone, render::ToneCurve::Aces);
}

TEST(Protocol, SettingsChangeAllOrNothing) {
  auto c = std::get<SessionConfig>(configFromHello(goodHello(), Limits{}, Defaults{}, testCatalog()));
  const auto before = c;
  v1::RenderSettings s;
  s.set_level(3);
  s.set_light_coefficients(1u << 20);  // over the limit: nothing applies
  const auto e = applySettings(c, s, Limits{}, testCatalog());
  ASSERT_TRUE(e);
  EXPECT_FALSE(e->fatal);
  EXPECT_EQ(c.level, before.level);
  s.set_light_coefficients(32);
  EXPECT_FALSE(applySettings(c, s, Limits{}, testCatalog()));
  EXPECT_EQ(c.level, 3);
  EXPECT_EQ(c.lightCoefficients, 32u);
}

// Automatic levels (RenderSettings.level_mode): the server's default at
// Hello, a level alone a fixed level as before the field, a mode with level
// 0 the level in effect (as the level or the cap), a cap checked as a level
// is; the renderer differs between a fixed level and the same cap.
TEST(Protocol, LevelModeIsAutomaticOrFixedCompatibly) {
  Defaults defaults;
  defaults.level = 6;
  defaults.automaticLevel = true;
  auto c = std::get<SessionConfig>(configFromHello(goodHello(), Limits{}, defaults, testCatalog()));
  EXPECT_TRUE(c.automaticLevel);
  EXPECT_EQ(c.level, 6);
  EXPECT_EQ(settingsToWire(c).level_mode(), v1::LEVEL_MODE_AUTO);
  EXPECT_EQ(settingsToWire(c).level(), 6u);
  const std::string automaticKey = c.rendererKey();
  v1::RenderSettings levelOnly;  // an older client's
  levelOnly.set_level(6);
  ASSERT_FALSE(applySettings(c, levelOnly, Limits{}, testCatalog()));
  EXPECT_FALSE(c.automaticLevel) << "a level alone is a fixed level";
  EXPECT_NE(c.rendererKey(), automaticKey);
  EXPECT_EQ(settingsToWire(c).level_mode(), v1::LEVEL_MODE_FIXED);
  v1::RenderSettings unchanged;  // neither: nothing changes
  unchanged.set_light_coefficients(32);
  ASSERT_FALSE(applySettings(c, unchanged, Limits{}, testCatalog()));
  EXPECT_FALSE(c.automaticLevel);
  v1::RenderSettings backToAuto;
  backToAuto.set_level_mode(v1::LEVEL_MODE_AUTO);
  ASSERT_FALSE(applySettings(c, backToAuto, Limits{}, testCatalog()));
  EXPECT_TRUE(c.automaticLevel);
  EXPECT_EQ(c.level, 6) << "level 0: the level in effect, now the cap";
  EXPECT_EQ(c.rendererKey(), automaticKey);
  v1::RenderSettings cap;
  cap.set_level_mode(v1::LEVEL_MODE_AUTO);
  cap.set_level(5);
  ASSERT_FALSE(applySettings(c, cap, Limits{}, testCatalog()));
  EXPECT_TRUE(c.automaticLevel);
  EXPECT_EQ(c.level, 5);
  Limits limits;
  limits.maxLevel = 6;
  cap.set_level(7);
  const auto tooFine = applySettings(c, cap, limits, testCatalog());
  ASSERT_TRUE(tooFine);
  EXPECT_EQ(tooFine->code, v1::ERROR_CODE_BAD_SETTINGS);
  EXPECT_NE(tooFine->message.find("level cap 7 is outside"), std::string::npos) << tooFine->message;
  EXPECT_EQ(c.level, 5) << "all or nothing";
  v1::RenderSettings bad;
  bad.set_level_mode(static_cast<v1::LevelMode>(9));
  const auto unknown = applySettings(c, bad, Limits{}, testCatalog());
  ASSERT_TRUE(unknown);
  EXPECT_NE(unknown->message.find("level_mode 9"), std::string::npos) << unknown->message;
  EXPECT_NE(unknown->message.find("AUTO = 2"), std::string::npos) << unknown->message;
  v1::RenderSettings fixed;
  fixed.set_level_mode(v1::LEVEL_MODE_FIXED);
  ASSERT_FALSE(applySettings(c, fixed, Limits{}, testCatalog()));
  EXPECT_FALSE(c.automaticLevel);
  EXPECT_EQ(c.level, 5) << "level 0: the cap in effect, now the level";
  // The scene info says each object's level where the renderer knows it.
  const v1::SceneInfo info = sceneInfo(c, testCatalog(), {5, 6});
  ASSERT_GE(info.objects_size(), 2);
  EXPECT_EQ(info.objects(0).level(), 5u);
  EXPECT_EQ(info.objects(1).level(), 6u);
  EXPECT_EQ(sceneInfo(c, testCatalog()).objects(0).level(), 0u) << "0: not known yet";
}

// A resized client window: RenderSettings.width and height change the frame
// size mid-session under Hello's rules (the limits, the pixel budget, even
// for H.264), all or nothing, never fatal; the renderer stays the same.
TEST(Protocol, SettingsResizeTheFramesWithinTheLimits) {
  Limits limits;
  limits.maxWidth = 800;
  limits.maxHeight = 600;
  limits.maxPixels = 400 * 300;
  auto c = std::get<SessionConfig>(configFromHello(goodHello(), limits, Defaults{}, testCatalog()));
  const std::string key = c.rendererKey();
  v1::RenderSettings s;
  s.set_width(400);
  s.set_height(300);
  EXPECT_FALSE(applySettings(c, s, limits, testCatalog()));
  EXPECT_EQ(c.width, 400);
  EXPECT_EQ(c.height, 300);
  EXPECT_EQ(c.rendererKey(), key) << "a new size needs no new renderer";
  EXPECT_EQ(settingsToWire(c).width(), 400u);
  EXPECT_EQ(settingsToWire(c).height(), 300u);

  const auto refused = [&](std::uint32_t w, std::uint32_t h, const std::string& words) {
    v1::RenderSettings bad;
    bad.set_width(w);
    bad.set_height(h);
    bad.set_level(3);  // all or nothing: not applied either
    const SessionConfig before = c;
    const auto e = applySettings(c, bad, limits, testCatalog());
    ASSERT_TRUE(e) << w << "x" << h << " accepted";
    EXPECT_EQ(e->code, v1::ERROR_CODE_BAD_RESOLUTION);
    EXPECT_FALSE(e->fatal);
    EXPECT_NE(e->message.find(words), std::string::npos) << e->message;
    EXPECT_EQ(c.width, before.width);
    EXPECT_EQ(c.height, before.height);
    EXPECT_EQ(c.level, before.level);
  };
  refused(801, 100, "801x100 is outside 1x1..800x600");
  refused(500, 300, "150000 pixels, over the server's 120000 per session");
  refused(320, 0, "set both width and height, or neither");
  refused(0, 200, "set both width and height, or neither");

  auto h264 = goodHello();
  h264.set_encoding(v1::ENCODING_H264);
  c = std::get<SessionConfig>(configFromHello(h264, limits, Defaults{}, testCatalog()));
  EXPECT_NE(c.level, 3);
  refused(321, 200, "321x200 is odd: ENCODING_H264 needs an even width and height");
}

// A session that sets no H.264 bitrate gets one that follows its frame size
// and rate; one it set stays through a resize.
TEST(Protocol, TheDefaultH264BitrateFollowsTheSize) {
  EXPECT_EQ(defaultH264BitrateKbps(1280, 720, 30), 2765);
  EXPECT_EQ(defaultH264BitrateKbps(1920, 1080, 30), 6221);
  EXPECT_EQ(defaultH264BitrateKbps(1920, 1080, 60), 12442);
  EXPECT_EQ(defaultH264BitrateKbps(256, 256, 30), kMinDefaultH264BitrateKbps);
  EXPECT_EQ(defaultH264BitrateKbps(2048, 2048, 60), kMaxDefaultH264BitrateKbps);

  Limits limits;
  auto h = goodHello();
  h.set_encoding(v1::ENCODING_H264);
  h.set_width(640);
  h.set_height(360);
  h.set_fps_cap(30);
  auto c = std::get<SessionConfig>(configFromHello(h, limits, Defaults{}, testCatalog()));
  EXPECT_EQ(h264Settings(c).bitrateKbps, kMinDefaultH264BitrateKbps);
  v1::RenderSettings s;
  s.set_width(1920);
  s.set_height(1080);
  ASSERT_FALSE(applySettings(c, s, limits, testCatalog()));
  EXPECT_EQ(h264Settings(c).bitrateKbps, 6221);
  EXPECT_EQ(settingsToWire(c).h264_bitrate_kbps(), 6221u) << "Frame.settings says the cap in effect";
  s.Clear();
  s.set_h264_bitrate_kbps(1500);
  ASSERT_FALSE(applySettings(c, s, limits, testCatalog()));
  s.Clear();
  s.set_width(1280);
  s.set_height(720);
  ASSERT_FALSE(applySettings(c, s, limits, testCatalog()));
  EXPECT_EQ(h264Settings(c).bitrateKbps, 1500) << "a bitrate the client set is kept";
}

TEST(Protocol, LatestPoseWinsAndBadPosesChangeNothing) {
  PoseState state = initialPose(render::Camera{}, {render::Pose{}, render::Pose{}});
  v1::PoseUpdate u;
  u.set_sequence(5);
  u.mutable_camera()->mutable_eye()->set_z(7);
  auto* o = u.add_objects();
  o->set_object(1);
  o->mutable_rotate_degrees()->set_y(30);
  u.set_client_time_ms(123);
  EXPECT_FALSE(applyPose(state, u));
  EXPECT_EQ(state.sequence, 5u);
  EXPECT_EQ(state.camera.eye, glm::dvec3(0, 0, 7));
  EXPECT_EQ(state.poses[1].rotateDegrees.y, 30);
  EXPECT_EQ(state.clientTimeMs, 123);

  v1::PoseUpdate stale;
  stale.set_sequence(4);
  stale.mutable_camera()->mutable_eye()->set_z(1);
  EXPECT_FALSE(applyPose(state, stale));
  EXPECT_EQ(state.camera.eye.z, 7);  // ignored

  v1::PoseUpdate bad;
  bad.set_sequence(6);
  bad.mutable_camera()->mutable_eye()->set_z(2);
  bad.add_objects()->set_object(9);
  const auto e = applyPose(state, bad);
  ASSERT_TRUE(e);
  EXPECT_NE(e->message.find("object 9"), std::string::npos);
  EXPECT_EQ(state.sequence, 5u);
  EXPECT_EQ(state.camera.eye.z, 7);

  v1::PoseUpdate nan;
  nan.set_sequence(7);
  nan.mutable_light_rotate_degrees()->set_x(std::numeric_limits<double>::infinity());
  EXPECT_TRUE(applyPose(state, nan));

  SessionConfig config;
  config.width = 64;
  config.height = 32;
  const auto request = frameRequest(state, config);
  EXPECT_EQ(request.width, 64);
  EXPECT_EQ(request.poses.size(), 2u);
  EXPECT_EQ(request.camera.eye.z, 7);
}

// A fused frame carries what its pixels cost: the directions summed a
// sample, and the share of samples whose sum came from their neighbours.
TEST(Protocol, AFrameSaysItsDirectionsAndItsSmoothShare) {
  render::Frame frame;
  frame.width = frame.height = 4;
  frame.passSamples = 8;
  frame.passDirections = 2000;
  frame.smoothSamples = 2;
  v1::ServerMessage m;
  ASSERT_TRUE(m.ParseFromString(frameMessage(SessionConfig{}, frame, "jpeg bytes", FrameFacts{})));
  ASSERT_TRUE(m.has_frame());
  EXPECT_EQ(m.frame().directions_per_sample(), 250.0);
  EXPECT_EQ(m.frame().smooth_share(), 0.25);
  frame.passSamples = 0;  // no fused pass: neither
  ASSERT_TRUE(m.ParseFromString(frameMessage(SessionConfig{}, frame, "jpeg bytes", FrameFacts{})));
  EXPECT_EQ(m.frame().directions_per_sample(), 0.0);
  EXPECT_EQ(m.frame().smooth_share(), 0.0);
}

}  // namespace
}  // namespace haarcast::net
