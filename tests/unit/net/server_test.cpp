// The server in process, on port 0, driven by Beast WebSocket clients: the
// round trip, every encoding, and each bad input of step 4. In each bad-input
// test a healthy session runs beside the bad one and must keep getting
// frames. Frames are 32×32 at level 4 on the CPU backend (built-in scene).
#include <future>

#include <sys/socket.h>

#include "haarcast/wire/exr_codec.h"
#include "haarcast/wire/frame_codec.h"
#include "server_fixture.h"

namespace haarcast::net::test {
namespace {

TEST(Server, HelloWelcomePoseFrame) {
  TestServer server;
  Client c(server.port());
  ASSERT_TRUE(c.connected());
  const auto w = c.handshake(hello(48, 32, v1::ENCODING_JPEG, 20));
  EXPECT_EQ(w.protocol_version(), kProtocolVersion);
  EXPECT_EQ(w.width(), 48u);
  EXPECT_EQ(w.height(), 32u);
  EXPECT_EQ(w.encoding(), v1::ENCODING_JPEG);
  EXPECT_EQ(w.object_count(), render::defaultScene().objects.size());
  EXPECT_EQ(w.settings().level(), 4u);
  EXPECT_FALSE(w.session_id().empty());
  EXPECT_FALSE(w.device().empty());
  ASSERT_EQ(w.scenes_size(), 1);
  EXPECT_EQ(w.scenes(0), "default");
  EXPECT_GE(w.materials_size(), 4);

  c.send(pose(7, 30));
  // The first frame may answer the scene's own pose (sent right after
  // Welcome); the one answering pose 7 must follow.
  std::optional<v1::ServerMessage> f;
  for (int i = 0; i < 3; ++i) {
    f = c.expect(v1::ServerMessage::kFrame);
    ASSERT_TRUE(f);
    if (f->frame().pose_sequence() == 7) break;
  }
  ASSERT_EQ(f->frame().pose_sequence(), 7u);
  EXPECT_EQ(f->frame().client_time_ms(), 1007.0);
  EXPECT_EQ(f->frame().width(), 48u);
  EXPECT_EQ(f->frame().height(), 32u);
  EXPECT_GE(f->frame().sequence(), 1u);
  EXPECT_GE(f->frame().server_ms(), 0.0);
  const auto image = wire::decodeJpeg(f->frame().data());
  EXPECT_EQ(image.width, 48u);
  EXPECT_EQ(image.height, 32u);
  std::vector<std::string> stages;
  for (const auto& t : f->frame().timings()) stages.push_back(t.name());
  EXPECT_NE(std::find(stages.begin(), stages.end(), "encode"), stages.end());
  EXPECT_NE(std::find(stages.begin(), stages.end(), "triple-product"), stages.end());

  // Stats every statsSeconds.
  const auto stats = c.expect(v1::ServerMessage::kStats, 5s);
  ASSERT_TRUE(stats);
  EXPECT_GE(stats->stats().frames_sent(), 1u);
  EXPECT_GT(stats->stats().bytes_sent(), 0u);
  EXPECT_EQ(stats->stats().sessions(), 1u);

  // Ping → Pong with the nonce.
  v1::ClientMessage ping;
  ping.mutable_ping()->set_nonce(99);
  c.send(ping);
  const auto pong = c.expect(v1::ServerMessage::kPong);
  ASSERT_TRUE(pong);
  EXPECT_EQ(pong->pong().nonce(), 99u);

  const std::string metrics = httpGet(server.port(), "/metrics");
  EXPECT_NE(metrics.find("haarcast_sessions 1"), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("haarcast_stage_seconds_count{stage=\"encode\"}"), std::string::npos) << metrics;
  EXPECT_EQ(metrics.find("haarcast_frames_total 0\n"), std::string::npos) << metrics;
}

// Frames come at most at the session's fps cap, and a burst of poses gives
// a frame of the newest, not a frame each.
TEST(Server, PacedToFpsCapAndLatestPoseWins) {
  TestServer server;
  Client c(server.port());
  c.handshake(hello(32, 32, v1::ENCODING_JPEG, 2));  // 0.5 s between frame starts at least
  ASSERT_TRUE(c.expect(v1::ServerMessage::kFrame));  // the scene's own view
  const auto t0 = Clock::now();
  std::uint64_t sequence = 0;
  for (int i = 0; i < 5; ++i) {
    c.send(pose(++sequence));
    auto f = c.expect(v1::ServerMessage::kFrame);
    ASSERT_TRUE(f);
  }
  // Five frames, four full intervals after t0 (a 32² frame renders in ~0.1 s).
  EXPECT_GE(std::chrono::duration<double>(Clock::now() - t0).count(), 4 * 0.5);

  for (int i = 0; i < 30; ++i) c.send(pose(++sequence));
  int frames = 0;
  for (;;) {
    auto f = c.expect(v1::ServerMessage::kFrame);
    ASSERT_TRUE(f);
    ++frames;
    if (f->frame().pose_sequence() == sequence) break;
  }
  EXPECT_LE(frames, 3) << "poses were queued, not merged";
}

// Every encoding of one pose: RAW is the tonemapped image, PNG decodes to
// exactly it, JPEG to close to it, and EXR's linear values tonemap to it.
TEST(Server, EncodingsAgree) {
  TestServer server;
  std::map<v1::Encoding, std::string> data;
  std::map<v1::Encoding, double> exposure;
  for (const auto e : {v1::ENCODING_RAW_RGBA8, v1::ENCODING_PNG, v1::ENCODING_JPEG, v1::ENCODING_EXR}) {
    Client c(server.port());
    // A fixed exposure: auto exposure eases from the session's earlier
    // frames, which differ between sessions in how many came before pose 1.
    auto h = hello(32, 32, e);
    h.mutable_hello()->mutable_settings()->set_exposure_mode(v1::EXPOSURE_MODE_FIXED);
    h.mutable_hello()->mutable_settings()->set_exposure_stops(-1.5);
    c.handshake(h);
    c.send(pose(1, 45));
    for (int i = 0; i < 3; ++i) {
      auto f = c.expect(v1::ServerMessage::kFrame);
      ASSERT_TRUE(f);
      EXPECT_EQ(f->frame().encoding(), e);
      if (f->frame().pose_sequence() == 1) {
        data[e] = f->frame().data();
        exposure[e] = f->frame().exposure_stops();
        break;
      }
    }
  }
  const std::string& raw = data[v1::ENCODING_RAW_RGBA8];
  ASSERT_EQ(raw.size(), 32u * 32u * 4u);
  const std::vector<std::uint8_t> rgba(raw.begin(), raw.end());
  EXPECT_EQ(wire::decodePng(data[v1::ENCODING_PNG]).pixels, rgba);
  const auto jpeg = wire::decodeJpeg(data[v1::ENCODING_JPEG]);
  ASSERT_EQ(jpeg.pixels.size(), rgba.size());
  double error = 0;
  for (std::size_t i = 0; i < rgba.size(); ++i) error += std::abs(int(jpeg.pixels[i]) - int(rgba[i]));
  EXPECT_LT(error / static_cast<double>(rgba.size()), 12.0);
  wire::LinearImage exr = wire::decodeExr(data[v1::ENCODING_EXR]);
  const io::RgbImage linear{static_cast<int>(exr.width), static_cast<int>(exr.height), std::move(exr.rgb)};
  for (const auto& [e, stops] : exposure) EXPECT_EQ(stops, -1.5) << v1::Encoding_Name(e);
  const auto fromExr = render::tonemapRgba8(linear, -1.5);
  ASSERT_EQ(fromExr.size(), rgba.size());
  int worst = 0;
  for (std::size_t i = 0; i < rgba.size(); ++i) worst = std::max(worst, std::abs(int(fromExr[i]) - int(rgba[i])));
  EXPECT_LE(worst, 1);  // half rounding moves an 8-bit level at most by one
}

TEST(Server, SettingsChangeTakesEffectAndBadOnesAreNotFatal) {
  TestServer server;
  Client c(server.port());
  c.handshake();
  v1::ClientMessage bad;
  (*bad.mutable_scene()->mutable_object_materials())[0] = "merl:unobtainium";
  c.send(bad);
  c.expectError(v1::ERROR_CODE_UNKNOWN_MATERIAL, false);
  v1::ClientMessage s;
  s.mutable_settings()->set_level(3);
  c.send(s);
  for (int i = 0; i < 5; ++i) {
    c.send(pose(static_cast<std::uint64_t>(10 + i)));
    auto f = c.expect(v1::ServerMessage::kFrame);
    ASSERT_TRUE(f);
    if (f->frame().settings().level() == 3) return;
  }
  FAIL() << "no frame at level 3";
}

// Welcome names the scene, its objects and their materials and quotes the
// server's limits; a material change is announced with a SceneInfo; frames
// carry the exposure they were made with, automatic by default.
TEST(Server, WelcomeDescribesTheSceneAndAMaterialChangeIsAnnounced) {
  TestServer server;
  Client c(server.port());
  const v1::Welcome w = c.handshake();
  const render::Scene scene = render::defaultScene();
  EXPECT_EQ(w.scene_info().name(), "default");
  ASSERT_EQ(static_cast<std::size_t>(w.scene_info().objects_size()), scene.objects.size());
  for (std::size_t i = 0; i < scene.objects.size(); ++i) {
    const auto& o = w.scene_info().objects(static_cast<int>(i));
    EXPECT_EQ(o.index(), i);
    EXPECT_EQ(o.name(), scene.objects[i].name);
    EXPECT_EQ(o.material(), scene.objects[i].material.name);
    EXPECT_EQ(o.pose().rotate_degrees().x(), scene.objects[i].pose.rotateDegrees.x);
    EXPECT_EQ(o.pose().translate().x(), scene.objects[i].pose.translate.x);
  }
  EXPECT_EQ(w.scene_info().camera().eye().z(), scene.camera.eye.z);
  EXPECT_EQ(w.scene_info().camera().fov_y_degrees(), scene.camera.fovYDegrees);
  const Limits limits;
  EXPECT_EQ(w.limits().min_level(), static_cast<std::uint32_t>(limits.minLevel));
  EXPECT_EQ(w.limits().max_level(), static_cast<std::uint32_t>(limits.maxLevel));
  EXPECT_GT(w.limits().max_width(), 0u);
  EXPECT_EQ(w.limits().max_exposure_stops(), render::kMaxExposureStops);
  EXPECT_EQ(w.settings().exposure_mode(), v1::EXPOSURE_MODE_AUTO);

  v1::ClientMessage change;
  (*change.mutable_scene()->mutable_object_materials())[1] = "lambert";
  c.send(change);
  const auto info = c.expect(v1::ServerMessage::kSceneInfo);
  ASSERT_TRUE(info);
  ASSERT_EQ(info->scene_info().objects_size(), w.scene_info().objects_size());
  EXPECT_EQ(info->scene_info().objects(0).material(), w.scene_info().objects(0).material());
  EXPECT_EQ(info->scene_info().objects(1).material(), "lambert");

  const auto f = c.expect(v1::ServerMessage::kFrame);
  ASSERT_TRUE(f);
  EXPECT_TRUE(std::isfinite(f->frame().exposure_stops()));
  EXPECT_NE(f->frame().exposure_stops(), 0.0) << "auto exposure measured nothing";
  EXPECT_EQ(f->frame().directions_per_sample(), 0.0) << "haar has no fused pass";
}

// A fused frame says how many map directions its pass summed a sample
// (render::Frame::passDirections): some, and at level 4 at most the map's 256.
TEST(Server, AFusedFrameSaysItsDirectionsASample) {
  TestServer server;
  Client c(server.port());
  c.handshake();
  v1::ClientMessage s;
  s.mutable_settings()->set_method(v1::ROTATION_METHOD_FUSED);
  c.send(s);
  for (int i = 0; i < 5; ++i) {
    c.send(pose(static_cast<std::uint64_t>(10 + i)));
    auto f = c.expect(v1::ServerMessage::kFrame);
    ASSERT_TRUE(f);
    if (f->frame().settings().method() != v1::ROTATION_METHOD_FUSED) continue;
    EXPECT_GT(f->frame().directions_per_sample(), 0.0);
    EXPECT_LE(f->frame().directions_per_sample(), 256.0);
    return;
  }
  FAIL() << "no fused frame";
}

// ---------------------------------------------------------------- HTTP

TEST(Server, HttpEndpoints) {
  TestServer server;
  http::status status{};
  EXPECT_EQ(httpGet(server.port(), "/healthz", &status), "ok\n");
  EXPECT_EQ(status, http::status::ok);
  const std::string metrics = httpGet(server.port(), "/metrics", &status);
  EXPECT_EQ(status, http::status::ok);
  for (const char* name : {"haarcast_sessions ", "haarcast_frames_total ", "haarcast_frames_dropped_total ",
                           "haarcast_bytes_total ", "# TYPE haarcast_stage_seconds summary"}) {
    EXPECT_NE(metrics.find(name), std::string::npos) << name;
  }
  httpGet(server.port(), "/../../etc/passwd", &status);
  EXPECT_EQ(status, http::status::not_found);
  httpGet(server.port(), "/nothing-here", &status);
  EXPECT_EQ(status, http::status::not_found);
}

// ---------------------------------------------------------------- bad input

TEST(ServerBadInput, WrongOrMissingTokenIs401) {
  TestServer server;
  HealthySession healthy(server.port());
  EXPECT_EQ(upgradeStatus(server.port(), "/ws?token=nope"), http::status::unauthorized);
  EXPECT_EQ(upgradeStatus(server.port(), "/ws"), http::status::unauthorized);
  EXPECT_EQ(upgradeStatus(server.port(), "/ws", "Bearer nope"), http::status::unauthorized);
  EXPECT_EQ(upgradeStatus(server.port(), std::string("/other?token=") + kToken), http::status::not_found);
  // Both ways of giving the right token are accepted.
  EXPECT_EQ(upgradeStatus(server.port(), "/ws", std::string("Bearer ") + kToken), http::status::switching_protocols);
  EXPECT_EQ(upgradeStatus(server.port(), std::string("/ws?token=") + kToken), http::status::switching_protocols);
  EXPECT_FALSE(Client(server.port(), "/ws?token=nope").connected());
  EXPECT_TRUE(healthy.waitForFrames(2));
}

TEST(ServerBadInput, GarbageTruncatedEmptyAndUnknownGetBadMessage) {
  TestServer server;
  HealthySession healthy(server.port());
  Client c(server.port());
  c.sendBytes(std::string("\xde\xad\xbe\xef\xff\xff\xff\xff\xff\xff\xff\x01", 12));
  c.expectError(v1::ERROR_CODE_BAD_MESSAGE, false);
  const std::string h = hello().SerializeAsString();
  c.sendBytes(h.substr(0, h.size() - 3));  // truncated
  c.expectError(v1::ERROR_CODE_BAD_MESSAGE, false);
  c.sendBytes("");  // an empty oneof
  const auto empty = c.expectError(v1::ERROR_CODE_BAD_MESSAGE, false);
  EXPECT_NE(empty.message().find("empty"), std::string::npos) << empty.message();
  // The session is still usable after non-fatal errors.
  c.handshake();
  c.sendBytes(std::string("\x98\x06\x01", 3));  // field 99: an unknown message type
  const auto unknown = c.expectError(v1::ERROR_CODE_BAD_MESSAGE, true);  // the 4th bad message: closed
  EXPECT_NE(unknown.message().find("field 99"), std::string::npos) << unknown.message();
  EXPECT_TRUE(healthy.waitForFrames(2));
}

TEST(ServerBadInput, OversizedMessages) {
  TestServer server;
  HealthySession healthy(server.port());
  {
    Client c(server.port());
    c.sendBytes(std::string(5000, 'x'));  // over the 4096-byte limit
    const auto e = c.expectError(v1::ERROR_CODE_MESSAGE_TOO_LARGE, true);
    EXPECT_NE(e.message().find("5000"), std::string::npos) << e.message();
  }
  {
    Client c(server.port());
    c.sendBytes(std::string(1u << 20, 'x'));  // far over: cut by the WebSocket layer
    EXPECT_FALSE(c.read(10s));
    EXPECT_FALSE(c.timedOut) << "the server did not close the session";
    // Close code 1009 when the close frame reaches the client before the
    // server's teardown resets the connection under the rest of the 1 MiB
    // it is still sending; a reset otherwise. Either way the server counted it.
    if (c.closeReason.code != websocket::close_code::none) {
      EXPECT_EQ(c.closeReason.code, websocket::close_code::too_big);
    }
  }
  // The client may see the reset before the server's read handler has
  // counted the cut: wait for the count rather than race it.
  const auto counted = [&] {
    return server.server().metrics().prometheusText().find("haarcast_errors_total{code=\"message_too_large\"} 2") !=
           std::string::npos;
  };
  for (int i = 0; i < 100 && !counted(); ++i) std::this_thread::sleep_for(50ms);
  EXPECT_TRUE(counted()) << server.server().metrics().prometheusText();
  EXPECT_TRUE(healthy.waitForFrames(2));
}

TEST(ServerBadInput, AbsurdResolutionAndOrder) {
  TestServer server;
  HealthySession healthy(server.port());
  {
    Client c(server.port());
    c.send(hello(100000, 100000));
    const auto e = c.expectError(v1::ERROR_CODE_BAD_RESOLUTION, true);
    EXPECT_NE(e.message().find("100000x100000"), std::string::npos) << e.message();
  }
  {
    Client c(server.port());
    c.send(hello(0, 32));
    c.expectError(v1::ERROR_CODE_BAD_RESOLUTION, true);
  }
  {
    Client c(server.port());
    c.send(pose(1));
    c.expectError(v1::ERROR_CODE_PROTOCOL_ORDER, true);
  }
  {
    Client c(server.port());
    auto h = hello();
    h.mutable_hello()->set_protocol_version(9);
    c.send(h);
    c.expectError(v1::ERROR_CODE_UNSUPPORTED_VERSION, true);
  }
  EXPECT_TRUE(healthy.waitForFrames(2));
}

// A client that stops reading: its frames are replaced in the slot (latest
// wins), its write stalls and it is cut; the healthy session never waits.
TEST(ServerBadInput, ClientThatStopsReading) {
  auto options = testOptions();
  options.writeStallSeconds = 3;  // long enough for frames to be replaced in the slot
  TestServer server(options);
  HealthySession healthy(server.port());
  Client slow(server.port(), std::string("/ws?token=") + kToken, 4096);
  slow.send(hello(256, 256, v1::ENCODING_RAW_RGBA8, 30));  // 256 KiB per frame
  // Looking away from the objects and up, over the ground's horizon: each
  // frame is the backdrop only, cheap to render (also under the sanitizers),
  // so the server produces far more bytes than the client takes.
  // Poses keep coming until the server cuts the session.
  const auto deadline = Clock::now() + 40s;
  bool open = false;
  for (std::uint64_t i = 1; Clock::now() < deadline && !slow.lastWriteError; ++i) {
    v1::ClientMessage m = pose(i);
    auto* cam = m.mutable_pose()->mutable_camera();
    cam->mutable_eye()->set_z(3);
    cam->mutable_target()->set_y(30);
    cam->mutable_target()->set_z(30);
    cam->mutable_up()->set_y(1);
    slow.send(m);
    const auto sessions = server.server().metrics().sessions.load();
    if (sessions == 2) open = true;
    if (open && sessions == 1) break;  // cut
    std::this_thread::sleep_for(40ms);
  }
  EXPECT_EQ(server.server().metrics().sessions.load(), 1) << "the stalled session is still open";
  EXPECT_GT(server.server().metrics().framesDropped.load(), 0u) << "no frame was replaced (latest wins)";
  const std::string metrics = server.server().metrics().prometheusText();
  EXPECT_NE(metrics.find("haarcast_errors_total{code=\"timeout\"}"), std::string::npos);
  EXPECT_NE(metrics.find("haarcast_timeouts_total{phase=\"write\"} 1"), std::string::npos);
  EXPECT_NE(metrics.find("haarcast_session_cuts_total{reason=\"write_stall\"} 1"), std::string::npos);
  // The healthy session went on all along, and still does.
  EXPECT_GE(healthy.frames(), 3);
  EXPECT_TRUE(healthy.waitForFrames(2));
}

TEST(ServerBadInput, ClientThatVanishesMidFrame) {
  TestServer server;
  HealthySession healthy(server.port());
  for (int i = 0; i < 3; ++i) {
    Client c(server.port());
    c.handshake(hello(64, 64));
    c.send(pose(1, 10));
    c.send(pose(2, 20));
    c.vanish();  // while its frame renders
  }
  EXPECT_TRUE(healthy.waitForFrames(3));
  const auto deadline = Clock::now() + 10s;
  while (Clock::now() < deadline && server.server().metrics().sessions.load() > 1) std::this_thread::sleep_for(50ms);
  EXPECT_EQ(server.server().metrics().sessions.load(), 1);
}

TEST(ServerBadInput, NoHelloTimesOut) {
  auto options = testOptions();
  options.handshakeSeconds = 0.5;
  TestServer server(options);
  Client c(server.port());
  ASSERT_TRUE(c.connected());
  const auto e = c.expectError(v1::ERROR_CODE_TIMEOUT, true);
  EXPECT_NE(e.message().find("Hello"), std::string::npos) << e.message();
}

TEST(ServerBadInput, TooManySessions) {
  auto options = testOptions();
  options.admission.sessions = 1;
  TestServer server(options);
  Client first(server.port());
  ASSERT_TRUE(first.connected());
  first.handshake();  // a Welcome: the first session is registered for sure
  Client second(server.port());
  ASSERT_TRUE(second.connected());
  second.send(hello());  // a session slot is taken (and refused) at the Hello
  second.expectError(v1::ERROR_CODE_TOO_MANY_SESSIONS, true);
}

// ---------------------------------------------------------------- shutdown

TEST(Server, StopDrainsSessions) {
  TestServer server;
  Client c(server.port());
  c.handshake();
  const auto t0 = Clock::now();
  server.server().stop();
  c.expectError(v1::ERROR_CODE_SHUTTING_DOWN, true);
  server.server().wait();
  EXPECT_LT(std::chrono::duration<double>(Clock::now() - t0).count(), 5.0);
  // The port is closed.
  asio::io_context ioc;
  tcp::socket s(ioc);
  beast::error_code ec;
  s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), server.port()), ec);
  EXPECT_TRUE(ec) << "still accepting after stop()";
}

}  // namespace
}  // namespace haarcast::net::test
