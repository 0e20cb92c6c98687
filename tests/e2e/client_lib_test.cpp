// Unit tests of haarcast-client's pure parts: URL and flag parsing, the pose
// path, the summary statistics, and the blank check on decoded frames (the
// decoders themselves: tests/unit/wire).
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "haarcast/client/client_options.h"
#include "haarcast/client/frame_image.h"
#include "haarcast/client/pose_path.h"
#include "haarcast/client/run_stats.h"
#include "haarcast/wire/encoding_name.h"
#include "haarcast/wire/frame_codec.h"
#include "haarcast/wire/frame_decode.h"

namespace haarcast::client {
namespace {

TEST(WsUrl, DefaultsThePathToTheWebSocketEndpoint) {
  const WsUrl u = parseWsUrl("ws://127.0.0.1:8080");
  EXPECT_EQ(u.host, "127.0.0.1");
  EXPECT_EQ(u.port, "8080");
  EXPECT_EQ(u.target, "/ws");
  EXPECT_EQ(parseWsUrl("ws://h:1?token=x").target, "/ws?token=x");
  EXPECT_EQ(parseWsUrl("ws://h:1/other/ws").target, "/other/ws");
  EXPECT_EQ(parseWsUrl("ws://example.org").port, "80");
  const WsUrl v6 = parseWsUrl("ws://[::1]:9000/ws");
  EXPECT_EQ(v6.host, "::1");
  EXPECT_EQ(v6.port, "9000");
}

TEST(WsUrl, RejectsWhatItCannotConnectTo) {
  EXPECT_THROW(parseWsUrl("http://h:1"), std::invalid_argument);
  EXPECT_THROW(parseWsUrl("ws://:80"), std::invalid_argument);
  EXPECT_THROW(parseWsUrl("ws://h:0"), std::invalid_argument);
  EXPECT_THROW(parseWsUrl("ws://h:65536"), std::invalid_argument);
  EXPECT_THROW(parseWsUrl("ws://h:8x"), std::invalid_argument);
  try {
    parseWsUrl("wss://h:1");
    FAIL() << "wss:// accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("wss://"), std::string::npos) << e.what();
  }
}

TEST(WsUrl, TokenQueryIsPercentEncoded) {
  EXPECT_EQ(withTokenQuery("/ws", "a b&c"), "/ws?token=a%20b%26c");
  EXPECT_EQ(withTokenQuery("/ws?x=1", "t"), "/ws?x=1&token=t");
}

TEST(Flags, SizeEncodingAndMethod) {
  const Size s = parseSize("320x200");
  EXPECT_EQ(s.width, 320u);
  EXPECT_EQ(s.height, 200u);
  for (const char* bad : {"320", "x200", "320x", "0x10", "-1x5", "3.5x4", "12x12x"}) {
    EXPECT_THROW(parseSize(bad), std::invalid_argument) << bad;
  }
  EXPECT_EQ(parseEncoding("jpeg"), v1::ENCODING_JPEG);
  EXPECT_EQ(parseEncoding("raw"), v1::ENCODING_RAW_RGBA8);
  EXPECT_THROW(parseEncoding("webp"), std::invalid_argument);
  for (auto e : {v1::ENCODING_JPEG, v1::ENCODING_PNG, v1::ENCODING_RAW_RGBA8, v1::ENCODING_EXR, v1::ENCODING_H264}) {
    EXPECT_EQ(parseEncoding(std::string(wire::encodingName(e))), e);  // names round-trip
  }
  try {
    parseEncoding("avc");
    ADD_FAILURE() << "\"avc\" was taken as an encoding";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("h264"), std::string::npos) << e.what();  // the valid choices
  }
  // H.264 frames are written decoded, as PNG: an access unit alone is no file.
  EXPECT_EQ(encodingFileExtension(v1::ENCODING_H264), ".png");
  EXPECT_EQ(parseMethod(""), v1::ROTATION_METHOD_UNSPECIFIED);
  for (auto m : {v1::ROTATION_METHOD_HAAR, v1::ROTATION_METHOD_SPATIAL, v1::ROTATION_METHOD_MATRIX,
                 v1::ROTATION_METHOD_TABLE, v1::ROTATION_METHOD_FUSED, v1::ROTATION_METHOD_SPLITSUM}) {
    EXPECT_EQ(parseMethod(methodName(m)), m);
  }
  EXPECT_EQ(methodName(v1::ROTATION_METHOD_SPLITSUM), "splitsum");
  EXPECT_EQ(parseMethod(""), v1::ROTATION_METHOD_UNSPECIFIED);
  // The names are the proto's (one table for both clients): a wrong one
  // lists every method the schema has.
  try {
    parseMethod("Haar");
    ADD_FAILURE() << "\"Haar\" was taken as a method";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("haar, spatial, matrix, table, fused or splitsum"), std::string::npos) << e.what();
  }
  // --tone: unset leaves the server's (Reinhard); a wrong name lists the valid ones.
  EXPECT_EQ(parseToneCurve(""), v1::TONE_CURVE_UNSPECIFIED);
  EXPECT_EQ(parseToneCurve("reinhard"), v1::TONE_CURVE_REINHARD);
  EXPECT_EQ(parseToneCurve("aces"), v1::TONE_CURVE_ACES);
  EXPECT_EQ(parseToneCurve("agx"), v1::TONE_CURVE_AGX);
  try {
    parseToneCurve("filmic");
    ADD_FAILURE() << "\"filmic\" was taken as a tone curve";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("reinhard, aces or agx"), std::string::npos) << e.what();
  }
}

// --level: a level is fixed, auto (with or without a cap) is automatic,
// unset is the server's; anything else names the valid forms.
TEST(Flags, LevelIsFixedAutomaticOrTheServers) {
  EXPECT_EQ(parseLevel("").mode, v1::LEVEL_MODE_UNSPECIFIED);
  EXPECT_EQ(parseLevel("0").level, 0u);
  EXPECT_EQ(parseLevel("5").level, 5u);
  EXPECT_EQ(parseLevel("5").mode, v1::LEVEL_MODE_FIXED);
  EXPECT_EQ(parseLevel("auto").level, 0u);
  EXPECT_EQ(parseLevel("auto").mode, v1::LEVEL_MODE_AUTO);
  EXPECT_EQ(parseLevel("auto:7").level, 7u);
  EXPECT_EQ(parseLevel("auto:7").mode, v1::LEVEL_MODE_AUTO);
  // The range is the server's: a level it does not serve is its error.
  EXPECT_EQ(parseLevel("9").level, 9u);
  for (const char* bad : {"auto:", "auto:0", "100", "-1", "5x", "fixed", "auto:6:7"}) {
    try {
      parseLevel(bad);
      ADD_FAILURE() << "\"" << bad << "\" was taken as a level";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("N, auto or auto:N"), std::string::npos) << e.what();
    }
  }
}

// The H.264 flags: for h264 only, and h264 wants an even size.
TEST(Flags, H264OptionsApplyToH264Only) {
  EXPECT_NO_THROW(checkH264Options(v1::ENCODING_H264, {256, 256}, {2000, 60}));
  EXPECT_NO_THROW(checkH264Options(v1::ENCODING_H264, {320, 200}, {}));
  EXPECT_NO_THROW(checkH264Options(v1::ENCODING_JPEG, {255, 255}, {}));  // odd is fine for JPEG
  const auto message = [](v1::Encoding e, Size size, H264Options o) {
    try {
      checkH264Options(e, size, o);
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(message(v1::ENCODING_JPEG, {256, 256}, {2000, 0}),
            "--bitrate applies to --encoding h264 only (got --encoding jpeg)");
  EXPECT_EQ(message(v1::ENCODING_PNG, {256, 256}, {0, 30}),
            "--keyframe-interval applies to --encoding h264 only (got --encoding png)");
  EXPECT_EQ(message(v1::ENCODING_H264, {255, 256}, {}),
            "--encoding h264 needs an even width and height (4:2:0 chroma), got --size 255x256");
  EXPECT_NE(message(v1::ENCODING_H264, {256, 99}, {}), "(accepted)");
}

double length(const v1::Vec3& v) { return std::sqrt(v.x() * v.x() + v.y() * v.y() + v.z() * v.z()); }

TEST(PosePath, OrbitStartsAtTheDefaultSceneCamera) {
  const PosePath path = PosePath::orbit(OrbitSweep{});
  const v1::PoseUpdate p = path.at(0, 100);
  EXPECT_NEAR(p.camera().eye().x(), 0.0, 1e-9);
  EXPECT_NEAR(p.camera().eye().y(), 0.85, 1e-3);
  EXPECT_NEAR(p.camera().eye().z(), 4.8, 1e-3);
  EXPECT_EQ(p.camera().fov_y_degrees(), 45.0);
  EXPECT_EQ(p.objects_size(), 0) << "no spin asked: the scene's object poses must stay untouched";
}

TEST(PosePath, OrbitSweepsTheWholeAngleOverTheRun) {
  OrbitSweep sweep;
  sweep.orbitDegrees = 360.0;
  sweep.spinDegrees = 180.0;
  sweep.lightDegrees = 90.0;
  const PosePath path = PosePath::orbit(sweep);
  // A quarter of the run: the camera at azimuth 90° is on +X.
  const v1::PoseUpdate q = path.at(25, 100);
  EXPECT_NEAR(q.camera().eye().z(), 0.0, 1e-9);
  EXPECT_GT(q.camera().eye().x(), 3.0);
  EXPECT_NEAR(length(q.camera().eye()), sweep.distance, 1e-9);
  ASSERT_EQ(q.objects_size(), 1);
  EXPECT_EQ(q.objects(0).object(), 0u);
  EXPECT_NEAR(q.objects(0).rotate_degrees().y(), 45.0, 1e-9);
  EXPECT_FALSE(q.objects(0).has_translate()) << "a spin must not move the object";
  EXPECT_NEAR(q.light_rotate_degrees().y(), 22.5, 1e-9);
  // Every pose differs from its neighbour, and the last one is not the first.
  EXPECT_NE(path.at(99, 100).camera().eye().x(), path.at(0, 100).camera().eye().x());
}

TEST(PosePath, OrbitRejectsDegenerateCameras) {
  OrbitSweep s;
  s.distance = 0.0;
  EXPECT_THROW(PosePath::orbit(s), std::invalid_argument);
  s = {};
  s.elevationDegrees = 90.0;
  EXPECT_THROW(PosePath::orbit(s), std::invalid_argument);
  s = {};
  s.fovYDegrees = 180.0;
  EXPECT_THROW(PosePath::orbit(s), std::invalid_argument);
}

TEST(PosePath, FileListsPosesAndCycles) {
  const auto doc = nlohmann::json::parse(R"({"poses": [
      {"camera": {"eye": [1, 2, 3], "fov_y_degrees": 50}},
      {"objects": [{"object": 1, "rotate_degrees": [10, 20, 30]}]},
      {"light_rotate_degrees": [0, 45, 0]}]})");
  const PosePath path = PosePath::fromJson(doc, "test.json");
  EXPECT_EQ(path.naturalLength(), 3u);
  const auto p0 = path.at(0, 3);
  EXPECT_EQ(p0.camera().eye().z(), 3.0);
  EXPECT_EQ(p0.camera().up().y(), 1.0) << "unset camera fields take the usual up vector";
  EXPECT_EQ(p0.camera().fov_y_degrees(), 50.0);
  EXPECT_FALSE(p0.has_light_rotate_degrees());
  const auto p1 = path.at(1, 3);
  EXPECT_FALSE(p1.has_camera());
  ASSERT_EQ(p1.objects_size(), 1);
  EXPECT_EQ(p1.objects(0).object(), 1u);
  EXPECT_EQ(p1.objects(0).rotate_degrees().z(), 30.0);
  EXPECT_EQ(path.at(5, 10).light_rotate_degrees().y(), 45.0) << "pose 5 of a 3-pose file is pose 2";
}

TEST(PosePath, FileErrorsNameThePoseAndField) {
  auto message = [](const char* text) {
    try {
      PosePath::fromJson(nlohmann::json::parse(text), "p.json");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"({"poses": []})").find("empty"), std::string::npos);
  EXPECT_NE(message(R"({"frames": []})").find("\"poses\""), std::string::npos);
  const std::string typo = message(R"({"poses": [{}, {"camera": {"eyes": [0, 0, 1]}}]})");
  EXPECT_NE(typo.find("poses[1].camera"), std::string::npos) << typo;
  EXPECT_NE(typo.find("eyes"), std::string::npos) << typo;
  const std::string bad = message(R"({"poses": [{"light_rotate_degrees": [0, "a", 0]}]})");
  EXPECT_NE(bad.find("poses[0].light_rotate_degrees"), std::string::npos) << bad;
  EXPECT_THROW(PosePath::fromFile("/nonexistent/path.json"), std::invalid_argument);
}

TEST(Quantile, InterpolatesBetweenRanks) {
  EXPECT_EQ(quantile({}, 0.5), 0.0);
  EXPECT_EQ(quantile({7.0}, 0.99), 7.0);
  EXPECT_DOUBLE_EQ(quantile({4.0, 1.0, 3.0, 2.0}, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(quantile({4.0, 1.0, 3.0, 2.0}, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(quantile({4.0, 1.0, 3.0, 2.0}, 1.0), 4.0);
  std::vector<double> hundred;
  for (int i = 1; i <= 101; ++i) hundred.push_back(i);
  EXPECT_DOUBLE_EQ(quantile(hundred, 0.99), 100.0);
  EXPECT_THROW(quantile({1.0}, 1.5), std::invalid_argument);
}

TEST(Summary, AggregatesClients) {
  RunSummary run;
  run.encoding = "jpeg";
  run.width = run.height = 256;
  run.wallSeconds = 2.0;
  SessionStats a;
  a.frames = 10;
  a.payloadBytes = 10000;
  a.wireBytes = 10500;
  a.latencyMs = {10, 10, 10, 10, 10, 20, 20, 20, 20, 20};
  a.firstPoseSeconds = 0.0;
  a.lastFrameSeconds = 2.0;
  a.stageMs["encode"] = {1.0, 3.0};
  SessionStats b = a;
  b.frames = 30;
  b.payloadBytes = 90000;
  b.dropped = 2;
  b.errors = 1;
  b.undecodedFrames = 3;
  b.keyframeRequests = 1;
  // The server's Stats: 12 frames sent between arrivals 0.5 s and 2.5 s apart.
  b.firstStats = std::pair{0.5, std::uint64_t{3}};
  b.lastStats = std::pair{2.5, std::uint64_t{15}};
  run.sessions = {a, b};
  const auto j = summaryJson(run);
  EXPECT_EQ(j["frames"], 40u);
  EXPECT_DOUBLE_EQ(j["fps"].get<double>(), 20.0);  // 40 frames over 2 s of wall time
  EXPECT_DOUBLE_EQ(j["bytes_per_frame"].get<double>(), 100000.0 / 40.0);
  EXPECT_DOUBLE_EQ(j["latency_ms_p50"].get<double>(), 15.0);
  EXPECT_DOUBLE_EQ(j["latency_ms_p99"].get<double>(), 20.0);
  EXPECT_EQ(j["dropped"], 2u);
  EXPECT_EQ(j["errors"], 1u);
  EXPECT_EQ(j["undecoded_frames"], 3u);
  EXPECT_EQ(j["keyframe_requests"], 1u);
  EXPECT_EQ(j["per_client"][1]["keyframe_requests"], 1u);
  EXPECT_EQ(j["encoding"], "jpeg");
  EXPECT_DOUBLE_EQ(j["stage_ms_mean"]["encode"].get<double>(), 2.0);
  EXPECT_EQ(j["clients"], 2u);
  ASSERT_EQ(j["per_client"].size(), 2u);
  EXPECT_DOUBLE_EQ(j["per_client"][1]["fps"].get<double>(), 15.0);
  EXPECT_DOUBLE_EQ(j["per_client"][1]["server_fps"].get<double>(), 6.0);
  EXPECT_TRUE(j["per_client"][0]["server_fps"].is_null()) << "no Stats: no figure, not 0";
  SessionStats one;
  one.firstStats = one.lastStats = std::pair{1.0, std::uint64_t{5}};
  EXPECT_FALSE(one.serverFps()) << "one Stats spans no time";
}

// ---- frames: the blank check and PAM on decoded frames ----

using wire::Rgba8Image;

Rgba8Image gradient(std::uint32_t w, std::uint32_t h) {
  Rgba8Image img{w, h, std::vector<std::uint8_t>(std::size_t{w} * h * 4)};
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x) {
      std::uint8_t* p = &img.pixels[(std::size_t{y} * w + x) * 4];
      p[0] = static_cast<std::uint8_t>(x * 255 / (w - 1));
      p[1] = static_cast<std::uint8_t>(y * 255 / (h - 1));
      p[2] = 64;
      p[3] = 255;
    }
  }
  return img;
}

Rgba8Image solid(std::uint32_t w, std::uint32_t h, std::uint8_t v) {
  return {w, h, std::vector<std::uint8_t>(std::size_t{w} * h * 4, v)};
}

std::string toJpeg(const Rgba8Image& img) { return wire::encodeJpeg(img.pixels, img.width, img.height, 90); }

TEST(FrameImage, AJpegGradientIsNotBlank) {
  const Rgba8Image fromJpeg = wire::decodeFrame(v1::ENCODING_JPEG, toJpeg(gradient(64, 48)), 64, 48);
  EXPECT_GT(pixelStats(fromJpeg).stddevLuma, 30.0);
}

TEST(FrameImage, BlankMeansNearlyConstant) {
  EXPECT_TRUE(isBlank(pixelStats(solid(32, 32, 0))));
  EXPECT_TRUE(isBlank(pixelStats(solid(32, 32, 200))));
  EXPECT_FALSE(isBlank(pixelStats(gradient(32, 32))));
  // One small bright object on black is not blank: 4×4 of 32×32 at 255.
  Rgba8Image dot = solid(32, 32, 0);
  for (int y = 14; y < 18; ++y) {
    for (int x = 14; x < 18; ++x) std::memset(&dot.pixels[(y * 32 + x) * 4], 255, 3);
  }
  EXPECT_FALSE(isBlank(pixelStats(dot)));
  // JPEG noise on a flat grey stays blank.
  const auto flat = toJpeg(solid(32, 32, 128));
  EXPECT_TRUE(isBlank(pixelStats(wire::decodeFrame(v1::ENCODING_JPEG, flat, 32, 32))));
}

TEST(FrameImage, PamHeaderRecordsTheSize) {
  const auto pam = encodePam(gradient(5, 3));
  const std::string header = "P7\nWIDTH 5\nHEIGHT 3\nDEPTH 4\nMAXVAL 255\nTUPLTYPE RGB_ALPHA\nENDHDR\n";
  ASSERT_EQ(pam.size(), header.size() + 5 * 3 * 4);
  EXPECT_EQ(std::string(pam.begin(), pam.begin() + static_cast<long>(header.size())), header);
}

}  // namespace
}  // namespace haarcast::client
