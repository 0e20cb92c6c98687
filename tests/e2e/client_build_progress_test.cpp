// haarcast-client and the server's BuildProgress: the stderr display
// (build_progress.h) with made-up times, and the session against a scripted
// server on loopback that sends BuildProgress and a message type newer than
// this client before its Welcome: each BuildProgress reaches the display,
// the unknown message is skipped, and the session plays its poses.
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>

#include "haarcast/client/build_progress.h"
#include "haarcast/client/pose_path.h"
#include "haarcast/client/session.h"

namespace haarcast::client {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

v1::BuildProgress progress(const std::string& stage, std::uint32_t index, std::uint64_t done, std::uint64_t total,
                           double left = 0.0, double elapsed = 0.0) {
  v1::BuildProgress p;
  p.set_stage(stage);
  p.set_stage_index(index);
  p.set_done(done);
  p.set_total(total);
  p.set_fraction(total ? static_cast<double>(done) / static_cast<double>(total) : 0.0);
  p.set_estimated_stage_seconds_left(left);
  p.set_elapsed_seconds(elapsed);
  return p;
}

TEST(BuildProgressText, StagePercentAndTheStagesEstimate) {
  EXPECT_EQ(buildProgressText(progress("visibility bunny", 1, 42, 100, 3.14)),
            "visibility bunny  42 % (~3.1 s left in this stage)");
  EXPECT_EQ(buildProgressText(progress("slices gold", 0, 0, 32)), "slices gold   0 %");
  EXPECT_EQ(buildProgressText(progress("slices gold", 0, 29, 100)), "slices gold  29 %") << "not 28: 0.29 × 100 < 29";
  EXPECT_EQ(buildProgressText(progress("slices gold", 0, 999, 1000, 0.01)), "slices gold  99 % (~0.0 s left in this stage)");
  EXPECT_EQ(buildProgressText(progress("slices gold", 0, 32, 32, 5.0)), "slices gold 100 %") << "done: no time left to say";
  EXPECT_EQ(buildProgressText(progress("rotators ring", 2, 5, 0)), "rotators ring") << "total unknown";
  EXPECT_EQ(buildProgressText(progress("visibility \x1b]0;owned\x07", 0, 1, 2, 75.0)),
            "visibility ?]0;owned?  50 % (~1 min 15 s left in this stage)")
      << "no escape sequence from the server reaches the terminal";
}

// With the server's plan (BuildProgress.stages): the whole build's share,
// the step counted in the plan, and the build's time left in place of the
// stage's.
TEST(BuildProgressText, WithAPlanTheBuildsShareStepAndTimeLeft) {
  v1::BuildProgress p = progress("visibility bunny", 1, 42, 100, 3.14);
  p.add_stages("slices bunny");
  p.add_stages("visibility bunny");
  p.add_stages("slices ground");
  p.set_build_fraction(0.456);
  p.set_estimated_build_seconds_left(12.0);
  EXPECT_EQ(buildProgressText(p), "visibility bunny  42 % · build 45 % (step 2 of 3), ~12 s left");
  p.set_estimated_build_seconds_left(0.0);
  p.set_build_fraction(1.0);
  p.set_stage("warm-up");
  EXPECT_EQ(buildProgressText(p), "warm-up  42 % · build 99 %") << "a stage outside the plan; never 100 before the end";
}

TEST(BuildProgressDisplay, OneRedrawnLineOnATerminal) {
  std::string out;
  BuildProgressDisplay d(true, [&](const std::string& s) { out += s; });
  d.ready(0.0);
  EXPECT_EQ(out, "") << "no build, nothing to say";
  d.update(progress("slices ball", 0, 1, 4, 0.0, 0.1), 10.0);
  d.update(progress("slices ball", 0, 2, 4, 0.4, 0.3), 10.2);
  EXPECT_TRUE(d.lineOpen());
  d.ready(10.5);
  EXPECT_EQ(out,
            "\rbuilding: slices ball  25 %\x1b[K"
            "\rbuilding: slices ball  50 % (~0.4 s left in this stage)\x1b[K"
            "\rbuilding: ready after 0.6 s\x1b[K\n");
  EXPECT_FALSE(d.lineOpen());
}

TEST(BuildProgressDisplay, PlainLinesAtEachStageEveryTenPercentOrFiveSeconds) {
  std::vector<std::string> lines;
  BuildProgressDisplay d(false, [&](const std::string& s) { lines.push_back(s); });
  double t = 0.0;
  for (std::uint64_t done = 0; done <= 40; ++done, t += 0.25) d.update(progress("visibility ball", 0, done, 100), t);
  d.update(progress("visibility ball", 0, 41, 100), t + 5.0);  // 5 s after the last line
  d.update(progress("visibility ring", 1, 0, 100), t + 5.1);  // a new stage
  d.ready(t + 6.0);
  EXPECT_EQ(lines, (std::vector<std::string>{
                       "building: visibility ball   0 %\n",
                       "building: visibility ball  10 %\n",
                       "building: visibility ball  20 %\n",
                       "building: visibility ball  30 %\n",
                       "building: visibility ball  40 %\n",
                       "building: visibility ball  41 %\n",
                       "building: visibility ring   0 %\n",
                       "building: ready after 0.9 s\n",
                   }));
}

// A scripted server: Hello → BuildProgress ×3, a message of a type this
// client does not know (field 99), Welcome, then a frame per pose.
void serveOneSession(tcp::acceptor& acceptor, std::string& error) {
  try {
    asio::io_context& io = static_cast<asio::io_context&>(acceptor.get_executor().context());
    websocket::stream<tcp::socket> ws(io);
    acceptor.accept(ws.next_layer());
    ws.accept();
    ws.binary(true);
    beast::flat_buffer buffer;
    auto read = [&](v1::ClientMessage& m) {
      buffer.consume(buffer.size());
      ws.read(buffer);
      return m.ParseFromArray(buffer.cdata().data(), static_cast<int>(buffer.size()));
    };
    auto write = [&](const std::string& bytes) { ws.write(asio::buffer(bytes)); };
    v1::ClientMessage m;
    if (!read(m) || !m.has_hello()) throw std::runtime_error("the first message is not a Hello");
    for (std::uint64_t done : {0, 10, 20}) {
      v1::ServerMessage b;
      *b.mutable_build_progress() = progress("visibility ball", 0, done, 20, 1.0, 0.1 * static_cast<double>(done));
      write(b.SerializeAsString());
    }
    write(std::string("\x9a\x06\x01x", 4));  // field 99, length-delimited, "x": a newer server's message
    v1::ServerMessage welcome;
    welcome.mutable_welcome()->set_protocol_version(v1::PROTOCOL_VERSION_1);
    welcome.mutable_welcome()->set_session_id("scripted");
    write(welcome.SerializeAsString());
    for (std::uint64_t sequence = 1;; ++sequence) {
      try {
        if (!read(m)) throw std::runtime_error("a message that is not a ClientMessage");
      } catch (const beast::system_error& e) {
        if (e.code() == websocket::error::closed) return;  // the client is done
        throw;
      }
      if (!m.has_pose()) continue;
      v1::ServerMessage frame;
      auto* f = frame.mutable_frame();
      f->set_sequence(sequence);
      f->set_pose_sequence(m.pose().sequence());
      f->set_width(8);
      f->set_height(8);
      f->set_encoding(v1::ENCODING_JPEG);
      f->set_data("not decoded: nothing checks or records it");
      write(frame.SerializeAsString());
    }
  } catch (const std::exception& e) {
    error = e.what();
  }
}

TEST(ClientSession, ShowsBuildProgressAndSkipsMessageTypesItDoesNotKnow) {
  asio::io_context serverIo;
  tcp::acceptor acceptor(serverIo, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  std::string serverError;
  std::thread server([&] { serveOneSession(acceptor, serverError); });

  const PosePath path = PosePath::orbit(OrbitSweep{});
  SessionConfig config;
  config.url = parseWsUrl("ws://127.0.0.1:" + std::to_string(acceptor.local_endpoint().port()));
  config.hello.set_protocol_version(v1::PROTOCOL_VERSION_1);
  config.path = &path;
  config.frames = 2;
  config.timeoutSeconds = 20;
  config.runStart = std::chrono::steady_clock::now();
  asio::io_context io;
  SessionStats stats;
  std::vector<std::string> events;  // "progress <done>" and "ready"
  Session session(
      io, 0, config, stats, [&](const FrameEvent&) { events.push_back("frame"); },
      [&](const std::string& m) { events.push_back("message " + m); },
      [&](std::size_t, const v1::BuildProgress* p) {
        events.push_back(p ? "progress " + std::to_string(p->done()) : "ready");
      });
  session.start();
  io.run();
  server.join();

  EXPECT_EQ(serverError, "");
  EXPECT_EQ(stats.failure, "");
  EXPECT_EQ(stats.frames, 2u);
  EXPECT_EQ(events, (std::vector<std::string>{"progress 0", "progress 10", "progress 20", "ready", "frame", "frame"}));
}

}  // namespace
}  // namespace haarcast::client
