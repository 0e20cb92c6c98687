// The application session without a socket: a recording SessionPort stands
// in for the WebSocket, a stub renderer for the render service, and the
// tests pass the clock, so Hello, settings, scenes, pacing and timeouts are
// checked message by message and instant by instant.
#include "haarcast/net/render_session.h"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>

#include <gtest/gtest.h>

#include "stub_renderer.h"

namespace haarcast::net {
namespace {

using namespace std::chrono_literals;

// Records everything the session emits.
class RecordingPort : public SessionPort {
 public:
  void send(std::string bytes) override { sent.push_back(parse(bytes)); }
  bool sendFrame(std::string bytes, std::size_t) override {
    frames.push_back(parse(bytes));
    return false;
  }
  std::size_t backlog() const override { return backlogSize; }
  void close(std::string error, CloseCode code, std::string reason) override {
    sent.push_back(parse(error));
    closeCode = code;
    closeReason = std::move(reason);
  }
  void armPace(Clock::time_point at) override { paceAt = at; }
  void prepare(const SessionConfig& config) override { prepared.push_back(config); }
  void render(FrameOrder order) override { orders.push_back(std::move(order)); }
  std::optional<ProtocolError> admit() override {
    if (full) return ProtocolError{v1::ERROR_CODE_TOO_MANY_SESSIONS, "too many sessions: the server allows 1", true};
    ++admitted;
    return std::nullopt;
  }
  void tokenRejected() override { ++wrongTokens; }
  void log(const std::string& line) override { logs.push_back(line); }

  static v1::ServerMessage parse(const std::string& bytes) {
    v1::ServerMessage m;
    EXPECT_TRUE(m.ParseFromString(bytes));
    return m;
  }

  std::deque<v1::ServerMessage> sent, frames;
  std::optional<CloseCode> closeCode;
  std::string closeReason;
  std::optional<Clock::time_point> paceAt;
  std::vector<SessionConfig> prepared;
  std::vector<FrameOrder> orders;
  bool full = false;
  std::size_t backlogSize = 0;  // control messages "waiting to be written"
  int admitted = 0, wrongTokens = 0;
  std::vector<std::string> logs;
};

Catalog catalog() {
  Catalog c;
  render::Camera camera;
  camera.eye = {0, 0, 3};
  for (const char* name : {"default", "other"}) {
    c.scenes.push_back({name, {"lambert", "lambert"}, camera, {render::Pose{}, render::Pose{}}, {"a", "b"}});
  }
  c.materials = {"lambert", "phong:16"};
  c.backends = {Backend::Cpu};
  return c;
}

ServerOptions options() {
  ServerOptions o;
  o.token = "t";
  o.limits.maxFps = 10;
  o.defaults.width = 16;
  o.defaults.height = 16;
  o.defaults.level = 4;
  o.handshakeSeconds = 2;
  o.idleSeconds = 30;
  o.statsSeconds = 1;
  return o;
}

v1::ClientMessage hello(double fps = 10) {
  v1::ClientMessage m;
  auto* h = m.mutable_hello();
  h->set_protocol_version(kProtocolVersion);
  h->set_fps_cap(fps);
  h->set_client_name("line one\nFORGED [serve] line");
  return m;
}

v1::ClientMessage pose(std::uint64_t sequence) {
  v1::ClientMessage m;
  m.mutable_pose()->set_sequence(sequence);
  m.mutable_pose()->mutable_light_rotate_degrees()->set_y(static_cast<double>(sequence));
  return m;
}

struct Fixture {
  ServerOptions o = options();
  Catalog c = catalog();
  Metrics metrics;
  RecordingPort port;
  Clock::time_point t0 = Clock::now();
  RenderSession session{o, c, metrics, port, "s1", t0};

  void receive(const v1::ClientMessage& m, Clock::time_point at) { session.onMessage(m.SerializeAsString(), true, at); }
  // Hello, and the renderer it asked for, ready at once.
  void welcome() {
    receive(hello(), t0);
    ASSERT_EQ(port.prepared.size(), 1u);
    session.onPrepared(port.prepared.back().rendererKey(), prepared(), "", t0);
  }
  static std::shared_ptr<PreparedRenderer> prepared(std::vector<int> levels = {}) {
    auto p = std::make_shared<PreparedRenderer>();
    p->renderer = std::make_unique<StubRenderer>(std::move(levels));
    return p;
  }
  // Runs the last order as a worker would and hands the frame back.
  void finishRender(Clock::time_point at) {
    ASSERT_FALSE(port.orders.empty());
    FrameOrder order = port.orders.back();
    auto request = session.takeRequest(*order.context);
    ASSERT_TRUE(request);
    RenderedFrame f;
    f.frame = order.renderer->renderer->render(*request);
    f.encoded = "jpeg";
    session.onRendered(*order.context, std::move(f), "", at);
  }
};

TEST(RenderSession, HelloIsWelcomedOnceTheRendererIsReady) {
  Fixture f;
  f.receive(hello(), f.t0);
  EXPECT_TRUE(f.port.sent.empty()) << "no Welcome before the renderer";
  EXPECT_EQ(f.port.admitted, 1);
  // A renderer for an older key (superseded) is ignored.
  f.session.onPrepared("another key", Fixture::prepared(), "", f.t0);
  EXPECT_TRUE(f.port.sent.empty());
  f.session.onPrepared(f.port.prepared.back().rendererKey(), Fixture::prepared(), "", f.t0);
  ASSERT_EQ(f.port.sent.size(), 1u);
  const auto& w = f.port.sent.front().welcome();
  EXPECT_EQ(w.session_id(), "s1");
  EXPECT_EQ(w.width(), 16u);
  EXPECT_EQ(w.object_count(), 2u);
  EXPECT_EQ(w.device(), "stub");
  EXPECT_EQ(w.scenes_size(), 2);
  // The client's name reaches the log escaped: no forged second line.
  bool logged = false;
  for (const auto& line : f.port.logs) {
    EXPECT_EQ(line.find('\n'), std::string::npos) << line;
    logged = logged || line.find("line one\\nFORGED") != std::string::npos;
  }
  EXPECT_TRUE(logged);
}

TEST(RenderSession, NoSlotWithoutAValidHello) {
  Fixture f;
  v1::ClientMessage bad = hello();
  bad.mutable_hello()->set_width(5000);
  bad.mutable_hello()->set_height(5000);
  f.receive(bad, f.t0);
  EXPECT_EQ(f.port.admitted, 0) << "an invalid Hello must not take a session slot";
  EXPECT_EQ(f.port.closeCode, CloseCode::PolicyError);

  Fixture full;
  full.port.full = true;
  full.receive(hello(), full.t0);
  ASSERT_EQ(full.port.sent.size(), 1u);
  EXPECT_EQ(full.port.sent.front().error().code(), v1::ERROR_CODE_TOO_MANY_SESSIONS);
  EXPECT_EQ(full.port.closeCode, CloseCode::TryAgainLater);
  EXPECT_TRUE(full.port.prepared.empty());

  Fixture wrong;
  v1::ClientMessage h = hello();
  h.mutable_hello()->set_auth_token("guess");
  wrong.receive(h, wrong.t0);
  EXPECT_EQ(wrong.port.wrongTokens, 1);
  EXPECT_EQ(wrong.port.sent.front().error().code(), v1::ERROR_CODE_UNAUTHORIZED);
}

TEST(RenderSession, BadSettingsNameTheChoicesAndAreNotFatal) {
  Fixture f;
  f.welcome();
  v1::ClientMessage m;
  m.mutable_settings()->set_backend(v1::BACKEND_VULKAN);  // not enabled here
  f.receive(m, f.t0);
  const auto& e = f.port.sent.back().error();
  EXPECT_EQ(e.code(), v1::ERROR_CODE_BAD_SETTINGS);
  EXPECT_FALSE(e.fatal());
  EXPECT_NE(e.message().find("enables cpu"), std::string::npos) << e.message();
  m.Clear();
  m.mutable_settings()->set_level(99);
  f.receive(m, f.t0);
  EXPECT_NE(f.port.sent.back().error().message().find("outside"), std::string::npos);
  EXPECT_FALSE(f.port.closeCode);
  EXPECT_EQ(f.port.prepared.size(), 1u) << "a refused change builds nothing";
}

TEST(RenderSession, SceneSwitchAnnouncesSceneInfoAndBuildsItsRenderer) {
  Fixture f;
  f.welcome();
  v1::ClientMessage m;
  m.mutable_scene()->set_scene("other");
  f.receive(m, f.t0);
  ASSERT_TRUE(f.port.sent.back().has_scene_info());
  EXPECT_EQ(f.port.sent.back().scene_info().name(), "other");
  ASSERT_EQ(f.port.prepared.size(), 2u);
  EXPECT_EQ(f.port.prepared.back().scene, "other");
  EXPECT_EQ(f.session.config().scene, "other");
  // Its build's progress follows the SceneInfo; the old renderer's build has none.
  f.session.onBuildProgress(f.port.prepared.front().rendererKey(), {"slices a", 0, 1, 2, 0.1, 0.0, 0.0, {}, 0.0});
  f.session.onBuildProgress(f.port.prepared.back().rendererKey(), {"slices b", 0, 1, 2, 0.1, 0.0, 0.0, {}, 0.0});
  EXPECT_EQ(f.port.sent.back().build_progress().stage(), "slices b");
  EXPECT_TRUE(f.port.sent[f.port.sent.size() - 2].has_scene_info());
  // The SceneInfo could not say the objects' levels (0); once the new
  // renderer is built, a second one does, and only when they changed.
  EXPECT_EQ(f.port.sent[f.port.sent.size() - 2].scene_info().objects(0).level(), 0u);
  f.session.onPrepared(f.port.prepared.back().rendererKey(), Fixture::prepared({6, 5}), "", f.t0);
  const auto levelsInfo = std::find_if(f.port.sent.rbegin(), f.port.sent.rend(),
                                       [](const v1::ServerMessage& s) { return s.has_scene_info(); });
  ASSERT_NE(levelsInfo, f.port.sent.rend());
  ASSERT_GE(levelsInfo->scene_info().objects_size(), 2);
  EXPECT_EQ(levelsInfo->scene_info().objects(0).level(), 6u);
  EXPECT_EQ(levelsInfo->scene_info().objects(1).level(), 5u);
  const auto infos = [&] {
    return std::count_if(f.port.sent.begin(), f.port.sent.end(), [](const v1::ServerMessage& s) { return s.has_scene_info(); });
  };
  const auto before = infos();
  f.session.onPrepared(f.port.prepared.back().rendererKey(), Fixture::prepared({6, 5}), "", f.t0);
  EXPECT_EQ(infos(), before) << "the same levels are not announced twice";
  // A material change on the same scene is a SceneChoice too: SceneInfo again.
  m.mutable_scene()->mutable_object_materials()->insert({1, "phong:16"});
  f.receive(m, f.t0);
  EXPECT_EQ(f.port.sent.back().scene_info().objects(1).material(), "phong:16");
}

// A resize (RenderSettings.width/height) keeps the renderer: no build, and
// the next frame comes at the new size.
TEST(RenderSession, AResizeKeepsTheRendererAndTheNextFrameHasTheNewSize) {
  Fixture f;
  f.welcome();
  f.finishRender(f.t0 + 5ms);
  ASSERT_EQ(f.port.frames.back().frame().width(), 16u);
  v1::ClientMessage m;
  m.mutable_settings()->set_width(64);
  m.mutable_settings()->set_height(48);
  f.receive(m, f.t0 + 200ms);
  EXPECT_EQ(f.port.prepared.size(), 1u) << "a new size builds nothing";
  ASSERT_EQ(f.port.orders.size(), 2u);
  EXPECT_EQ(f.port.orders.back().pixels, 64u * 48u);
  f.finishRender(f.t0 + 210ms);
  EXPECT_EQ(f.port.frames.back().frame().width(), 64u);
  EXPECT_EQ(f.port.frames.back().frame().height(), 48u);
  // A size past the limits is refused, not fatal, and nothing changes.
  m.mutable_settings()->set_width(100000);
  f.receive(m, f.t0 + 400ms);
  EXPECT_EQ(f.port.sent.back().error().code(), v1::ERROR_CODE_BAD_RESOLUTION);
  EXPECT_FALSE(f.port.sent.back().error().fatal());
  EXPECT_EQ(f.session.config().width, 64);
  EXPECT_FALSE(f.port.closeCode);
}

// Frame.server_ms is the server's time for the frame: a renderer build that
// the frame waited for, or the time a still view sat before a settings
// change, is not in it.
TEST(RenderSession, ServerMsNeverCountsABuildOrAnIdleSpell) {
  Fixture f;
  f.welcome();
  f.finishRender(f.t0 + 5ms);
  f.receive(pose(1), f.t0 + 200ms);
  f.finishRender(f.t0 + 230ms);
  EXPECT_NEAR(f.port.frames.back().frame().server_ms(), 30.0, 1e-6);
  // Another level: a build of 20 s; the frame after it took 40 ms.
  v1::ClientMessage m;
  m.mutable_settings()->set_level(3);
  f.receive(m, f.t0 + 1s);
  ASSERT_EQ(f.port.prepared.size(), 2u);
  f.session.onPrepared(f.port.prepared.back().rendererKey(), Fixture::prepared(), "", f.t0 + 21s);
  f.finishRender(f.t0 + 21s + 40ms);
  EXPECT_NEAR(f.port.frames.back().frame().server_ms(), 40.0, 1e-6);
  // A still view for a minute, then an exposure change (no pose): 25 ms.
  m.Clear();
  m.mutable_settings()->set_exposure_mode(v1::EXPOSURE_MODE_FIXED);
  m.mutable_settings()->set_exposure_stops(1.0);
  f.receive(m, f.t0 + 81s);
  f.finishRender(f.t0 + 81s + 25ms);
  EXPECT_NEAR(f.port.frames.back().frame().server_ms(), 25.0, 1e-6);
}

TEST(RenderSession, PosesArePacedToTheFpsCapAndTheLatestWins) {
  Fixture f;
  f.welcome();
  ASSERT_EQ(f.port.orders.size(), 1u);  // the first frame, at once
  f.finishRender(f.t0 + 5ms);
  ASSERT_EQ(f.port.frames.size(), 1u);
  // Two poses inside the 100 ms frame interval: no render yet, one timer.
  f.receive(pose(1), f.t0 + 10ms);
  f.receive(pose(2), f.t0 + 20ms);
  EXPECT_EQ(f.port.orders.size(), 1u);
  ASSERT_TRUE(f.port.paceAt);
  EXPECT_EQ(*f.port.paceAt, f.t0 + 100ms);
  f.session.onPace(f.t0 + 100ms);
  ASSERT_EQ(f.port.orders.size(), 2u);
  f.receive(pose(3), f.t0 + 101ms);  // arrives before the worker starts: the frame shows it
  f.finishRender(f.t0 + 110ms);
  EXPECT_EQ(f.port.frames.back().frame().pose_sequence(), 3u);
  EXPECT_EQ(f.port.frames.back().frame().sequence(), 2u);
  // A stale pose changes nothing.
  f.receive(pose(2), f.t0 + 300ms);
  EXPECT_EQ(f.port.orders.size(), 2u);
}

TEST(RenderSession, HelloTimeoutIdleTimeoutAndStats) {
  Fixture f;
  f.session.onTick(f.t0 + 1s);
  EXPECT_TRUE(f.port.sent.empty());
  f.session.onTick(f.t0 + 2100ms);
  ASSERT_EQ(f.port.sent.size(), 1u);
  EXPECT_EQ(f.port.sent.front().error().code(), v1::ERROR_CODE_TIMEOUT);
  EXPECT_NE(f.metrics.prometheusText().find("haarcast_timeouts_total{phase=\"hello\"} 1"), std::string::npos);

  Fixture g;
  g.welcome();
  g.session.onTick(g.t0 + 1s);
  EXPECT_TRUE(g.port.sent.back().has_stats());
  g.session.onTick(g.t0 + 31s);
  EXPECT_EQ(g.port.sent.back().error().code(), v1::ERROR_CODE_TIMEOUT);
  EXPECT_NE(g.port.sent.back().error().message().find("idle"), std::string::npos);
}

// A frame that takes long says how far it is (FrameProgress, from the
// render's StageMark), and one that does not, nothing.
TEST(RenderSession, AFrameInFlightPastHalfASecondSendsItsProgressUntilItEnds) {
  Fixture f;
  f.welcome();
  ASSERT_EQ(f.port.orders.size(), 1u);
  auto sent = [&] {
    return std::count_if(f.port.sent.begin(), f.port.sent.end(), [](const v1::ServerMessage& m) { return m.has_frame_progress(); });
  };
  // A frame of 300 ms: nothing.
  f.session.onTick(f.t0 + 200ms);
  f.finishRender(f.t0 + 300ms);
  EXPECT_EQ(sent(), 0);
  // The renderer's last frame (the render service keeps it): the weights.
  f.port.orders.back().renderer->setLastFrame({{{"gbuffer", 0.1}, {"fused", 0.9}}, 256});
  // The next one, ordered at 1 s, is slow.
  f.receive(pose(1), f.t0 + 1s);
  ASSERT_EQ(f.port.orders.size(), 2u);
  f.session.onTick(f.t0 + 1400ms);
  EXPECT_EQ(sent(), 0) << "not before half a second";
  render::StageMark& mark = f.port.orders.back().context->stage;
  mark.enter("fused", 4);
  mark.tick();
  mark.tick();
  f.session.onTick(f.t0 + 1500ms);
  ASSERT_EQ(sent(), 1);
  const auto& p = f.port.sent.back().frame_progress();
  EXPECT_EQ(p.stage(), "fused");
  EXPECT_DOUBLE_EQ(p.stage_fraction(), 0.5);
  EXPECT_DOUBLE_EQ(p.fraction(), 0.1 + 0.5 * 0.9);
  EXPECT_GT(p.estimated_seconds_left(), 0.0);
  EXPECT_EQ(p.width(), 16u);
  EXPECT_EQ(p.height(), 16u);
  f.session.onTick(f.t0 + 1600ms);
  EXPECT_EQ(sent(), 1) << "at most four a second";
  f.session.onTick(f.t0 + 1800ms);
  EXPECT_EQ(sent(), 2);
  // Behind a backlog: skipped.
  f.port.backlogSize = 4;
  f.session.onTick(f.t0 + 2100ms);
  EXPECT_EQ(sent(), 2);
  f.port.backlogSize = 0;
  // The frame ends it.
  f.finishRender(f.t0 + 2200ms);
  f.session.onTick(f.t0 + 3s);
  EXPECT_EQ(sent(), 2);
}

TEST(RenderSession, FatalErrorsCloseOnceWithAReasonCutOnUtf8) {
  Fixture f;
  f.welcome();
  v1::ClientMessage m;
  m.mutable_scene()->set_scene(std::string(200, 'x'));
  f.receive(m, f.t0);  // not fatal: an Error naming the scenes
  EXPECT_FALSE(f.port.closeCode);
  f.session.fail({v1::ERROR_CODE_BAD_MESSAGE, "é" + std::string(120, 'a') + "éé", true});
  ASSERT_TRUE(f.port.closeCode);
  EXPECT_LE(f.port.closeReason.size(), kMaxCloseReasonBytes);
  // Byte 123 falls inside the second "é": the cut drops it whole.
  EXPECT_EQ(f.port.closeReason, "é" + std::string(120, 'a'));
  const auto sent = f.port.sent.size();
  f.session.fail({v1::ERROR_CODE_TIMEOUT, "again", true});
  f.receive(pose(9), f.t0);
  EXPECT_EQ(f.port.sent.size(), sent) << "nothing after the close";
  EXPECT_NE(f.metrics.prometheusText().find("haarcast_session_cuts_total{reason=\"bad_message\"} 1"), std::string::npos);
}

// The errors in what was sent, in order.
std::vector<v1::Error> errorsIn(const std::deque<v1::ServerMessage>& sent) {
  std::vector<v1::Error> out;
  for (const auto& m : sent) {
    if (m.has_error()) out.push_back(m.error());
  }
  return out;
}

TEST(RenderSession, APoseThatFailsValidationIsNotKept) {
  Fixture f;
  f.welcome();
  f.finishRender(f.t0 + 5ms);
  // Finite, but past what the renderer takes: every later pose would fail.
  v1::ClientMessage huge;
  huge.mutable_pose()->set_sequence(1);
  auto* o = huge.mutable_pose()->add_objects();
  o->set_object(0);
  o->mutable_rotate_degrees()->set_x(1e308);
  o->mutable_rotate_degrees()->set_y(1e308);
  f.receive(huge, f.t0 + 10ms);
  v1::ClientMessage wide;  // a fov the protocol's old bound let through, the renderer's does not
  wide.mutable_pose()->set_sequence(2);
  wide.mutable_pose()->mutable_camera()->set_fov_y_degrees(175);
  f.receive(wide, f.t0 + 20ms);
  auto errors = errorsIn(f.port.sent);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].code(), v1::ERROR_CODE_BAD_MESSAGE);
  EXPECT_FALSE(errors[0].fatal());
  EXPECT_NE(errors[0].message().find("rotation is outside"), std::string::npos) << errors[0].message();
  // The wire's fov range is the renderer's (render::kMaxFovDegrees).
  EXPECT_NE(errors[1].message().find("fov_y_degrees 175 is outside 1..170"), std::string::npos) << errors[1].message();
  // A camera-only pose after them renders, with the object as it was.
  v1::ClientMessage camera;
  camera.mutable_pose()->set_sequence(3);
  camera.mutable_pose()->mutable_camera()->set_fov_y_degrees(50);
  f.receive(camera, f.t0 + 30ms);
  f.session.onPace(f.t0 + 100ms);
  ASSERT_EQ(f.port.orders.size(), 2u);
  const auto request = f.session.takeRequest(*f.port.orders.back().context);
  ASSERT_TRUE(request);
  ASSERT_FALSE(request->poses.empty());
  EXPECT_EQ(request->poses[0].rotateDegrees, glm::dvec3(0.0));
  EXPECT_EQ(request->camera.fovYDegrees, 50.0);
  EXPECT_NO_THROW(render::checkFrameRequest(*request, request->poses.size()));
}

TEST(RenderSession, RepeatedRenderErrorsAreResentWithACount) {
  Fixture f;
  f.welcome();
  const auto fail = [&](Clock::time_point at) {
    ASSERT_FALSE(f.port.orders.empty());
    FrameOrder order = f.port.orders.back();
    ASSERT_TRUE(f.session.takeRequest(*order.context));
    f.session.onRendered(*order.context, std::nullopt, "device lost", at);
  };
  fail(f.t0 + 5ms);
  ASSERT_EQ(errorsIn(f.port.sent).size(), 1u);
  // The same failure twice more within the second: folded, not dropped.
  for (int i = 1; i <= 2; ++i) {
    f.receive(pose(static_cast<std::uint64_t>(i)), f.t0 + i * 100ms + 1ms);
    f.session.onPace(f.t0 + i * 100ms + 5ms);
    fail(f.t0 + i * 100ms + 10ms);
  }
  EXPECT_EQ(errorsIn(f.port.sent).size(), 1u);
  // No frame comes to say it: the tick does, with the count.
  f.session.onTick(f.t0 + 1100ms);
  const auto errors = errorsIn(f.port.sent);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[1].code(), v1::ERROR_CODE_RENDER_FAILED);
  EXPECT_EQ(errors[1].message(), "device lost (2 more times since it was last said)");
  f.session.onTick(f.t0 + 2200ms);
  EXPECT_EQ(errorsIn(f.port.sent).size(), 2u) << "nothing new to say";
  EXPECT_NE(f.metrics.prometheusText().find("haarcast_render_failures_total 3"), std::string::npos);
}

// ------------------------------------------------------------------ renderer build progress

// A port whose prepare() goes to a real RenderService, with the test thread
// as the strand: the service's answers and progress wait in `posted` until
// pump() runs them, as session_jobs.h posts them to a transport's strand.
class ServicePort : public RecordingPort {
 public:
  ServicePort(RenderService& service, std::string owner) : service_(service), owner_(std::move(owner)) {}
  RenderSession* session = nullptr;

  void prepare(const SessionConfig& config) override {
    RecordingPort::prepare(config);
    const std::string key = config.rendererKey();
    service_.prepare(
        config, owner_,
        [this, key](PrepareOutcome o) {
          post([this, key, o] { session->onPrepared(key, o.renderer, o.error, Clock::now()); });
        },
        [this, key](const BuildProgressUpdate& u) { post([this, key, u] { session->onBuildProgress(key, u); }); });
  }
  // Runs what was posted, in order, until `done` holds; false after 10 s.
  bool pump(const std::function<bool()>& done) {
    const auto deadline = Clock::now() + 10s;
    std::unique_lock lock(mutex_);
    while (!done()) {
      if (!cv_.wait_until(lock, deadline, [&] { return !posted_.empty(); })) return false;
      auto task = std::move(posted_.front());
      posted_.pop_front();
      lock.unlock();
      task();
      lock.lock();
    }
    return true;
  }

 private:
  void post(std::function<void()> task) {
    {
      std::lock_guard lock(mutex_);
      posted_.push_back(std::move(task));
    }
    cv_.notify_one();
  }
  RenderService& service_;
  std::string owner_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<std::function<void()>> posted_;
};

TEST(RenderSession, AHelloForAnUncachedConfigGetsBuildProgressBeforeWelcome) {
  Metrics metrics;
  // Two stages of ten steps, 10 ms apart: about 0.2 s of build.
  AbandonableRendererBuilder builder = [](const SessionConfig&, const std::function<bool()>&,
                                          const render::RenderProgress& progress) {
    for (const char* stage : {"slices a", "visibility a"}) {
      for (std::size_t i = 0; i <= 10; ++i) {
        progress(stage, i, 10);
        std::this_thread::sleep_for(10ms);
      }
    }
    return Fixture::prepared();
  };
  RenderService::Options serviceOptions;
  serviceOptions.progressIntervalSeconds = 0.03;
  RenderService service(builder, serviceOptions, metrics);
  const ServerOptions o = options();
  const Catalog c = catalog();
  ServicePort port(service, "s1");
  RenderSession session(o, c, metrics, port, "s1", Clock::now());
  port.session = &session;
  session.onMessage(hello().SerializeAsString(), true, Clock::now());
  ASSERT_TRUE(port.pump([&] { return session.welcomed(); }));

  ASSERT_GE(port.sent.size(), 3u);
  EXPECT_TRUE(port.sent.back().has_welcome()) << port.sent.back().DebugString();
  std::vector<v1::BuildProgress> progress;
  std::vector<std::string> stages;
  for (std::size_t i = 0; i + 1 < port.sent.size(); ++i) {
    ASSERT_TRUE(port.sent[i].has_build_progress()) << "message " << i << " before Welcome: " << port.sent[i].DebugString();
    progress.push_back(port.sent[i].build_progress());
    if (stages.empty() || stages.back() != progress.back().stage()) stages.push_back(progress.back().stage());
  }
  EXPECT_EQ(stages, (std::vector<std::string>{"slices a", "visibility a"}));
  for (std::size_t i = 0; i < progress.size(); ++i) {
    const auto& p = progress[i];
    EXPECT_GE(p.fraction(), 0.0);
    EXPECT_LE(p.fraction(), 1.0);
    if (i == 0) continue;
    const auto& q = progress[i - 1];
    ASSERT_LE(q.stage_index(), p.stage_index()) << i;
    if (q.stage_index() == p.stage_index()) {
      EXPECT_LE(q.fraction(), p.fraction()) << i;
    }
  }

  // Another session with the same config: the renderer is cached, so the
  // Welcome comes with no BuildProgress before it.
  ServicePort port2(service, "s2");
  RenderSession session2(o, c, metrics, port2, "s2", Clock::now());
  port2.session = &session2;
  session2.onMessage(hello().SerializeAsString(), true, Clock::now());
  ASSERT_TRUE(port2.pump([&] { return session2.welcomed(); }));
  ASSERT_EQ(port2.sent.size(), 1u);
  EXPECT_TRUE(port2.sent.front().has_welcome());
}

TEST(RenderSession, BuildProgressWaitsBehindABacklogLatestOnlyAndEndsWithTheRenderer) {
  Fixture f;
  f.receive(hello(), f.t0);
  const std::string key = f.port.prepared.back().rendererKey();
  f.session.onBuildProgress("another key", {"slices a", 0, 1, 10, 0.1, 0.0, 0.0, {}, 0.0});
  EXPECT_TRUE(f.port.sent.empty()) << "a superseded build's progress is not this session's";
  f.session.onBuildProgress(key, {"slices a", 0, 1, 10, 0.1, 0.0, 0.0, {}, 0.0});
  ASSERT_EQ(f.port.sent.size(), 1u);
  EXPECT_TRUE(f.port.sent.back().has_build_progress());
  // A client that does not read: progress is held, the latest replacing
  // the one before, and sent once the backlog drains.
  f.port.backlogSize = 10;
  f.session.onBuildProgress(key, {"slices a", 0, 5, 10, 0.5, 0.4, 0.0, {}, 0.0});
  f.session.onBuildProgress(key, {"slices a", 0, 8, 10, 0.8, 0.1, 0.0, {}, 0.0});
  f.session.onTick(f.t0 + 100ms);
  EXPECT_EQ(f.port.sent.size(), 1u) << "held behind the backlog";
  f.port.backlogSize = 0;
  f.session.onSent(false, 0, f.t0 + 150ms);
  ASSERT_EQ(f.port.sent.size(), 2u);
  EXPECT_EQ(f.port.sent.back().build_progress().done(), 8u) << "the latest";
  f.session.onTick(f.t0 + 200ms);
  EXPECT_EQ(f.port.sent.size(), 2u) << "once";
  // Held again when the renderer comes: dropped, the Welcome goes, and
  // later progress (a race with the build's end) is ignored.
  f.port.backlogSize = 10;
  f.session.onBuildProgress(key, {"visibility a", 1, 3, 10, 0.9, 0.2, 0.0, {}, 0.0});
  f.port.backlogSize = 0;
  f.session.onPrepared(key, Fixture::prepared(), "", f.t0 + 300ms);
  f.session.onBuildProgress(key, {"visibility a", 1, 9, 10, 1.0, 0.0, 0.0, {}, 0.0});
  f.session.onTick(f.t0 + 400ms);
  ASSERT_EQ(f.port.sent.size(), 3u);
  EXPECT_TRUE(f.port.sent.back().has_welcome());
}

}  // namespace
}  // namespace haarcast::net
