// The CLI client's H.264 session against a scripted server on loopback: the
// server's own encoder (haarcast_net's H264Encoder) makes the stream, but the
// first frame the client gets is a delta frame whose keyframe it never saw,
// as after a lost start. The session must count that frame as undecoded, ask
// for a keyframe with its next pose (PoseUpdate.keyframe), decode every frame
// from the keyframe on, and send the H.264 settings of its Hello.
#include <cmath>
#include <cstdint>
#include <thread>
#include <vector>

#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <gtest/gtest.h>

#include "haarcast/client/frame_image.h"
#include "haarcast/net/h264_encoder.h"
#include "haarcast/client/pose_path.h"
#include "haarcast/client/session.h"

namespace haarcast::client {
namespace {

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;

constexpr int kSide = 128;

// A picture that is never blank: a gradient with a bright square that moves
// with t, so each frame differs from the one before.
std::vector<std::uint8_t> picture(int t) {
  std::vector<std::uint8_t> rgba(std::size_t(kSide) * kSide * 4);
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      std::uint8_t* p = &rgba[(std::size_t(y) * kSide + x) * 4];
      const bool square = std::abs(x - (20 + 8 * t) % kSide) < 12 && std::abs(y - 64) < 12;
      p[0] = square ? 240 : static_cast<std::uint8_t>(x);
      p[1] = square ? 220 : static_cast<std::uint8_t>(y);
      p[2] = static_cast<std::uint8_t>(128 + (x - y) / 4);
      p[3] = 255;
    }
  }
  return rgba;
}

// What the scripted server saw.
struct ServerLog {
  v1::Hello hello;
  std::vector<std::uint64_t> poses;           // every pose's sequence, in order
  std::vector<std::uint64_t> keyframePoses;   // those with PoseUpdate.keyframe
  std::vector<bool> sentKeyframe;             // per frame sent
  std::string error;
};

// One session: Hello → Welcome, then one H.264 frame per pose. The first
// frame's keyframe is encoded and withheld; a pose with `keyframe` gets one.
void serveOneSession(tcp::acceptor& acceptor, ServerLog& log) {
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
    auto write = [&](const v1::ServerMessage& m) { ws.write(asio::buffer(m.SerializeAsString())); };

    v1::ClientMessage first;
    if (!read(first) || !first.has_hello()) throw std::runtime_error("the first message is not a Hello");
    log.hello = first.hello();
    v1::ServerMessage welcome;
    auto* w = welcome.mutable_welcome();
    w->set_protocol_version(v1::PROTOCOL_VERSION_1);
    w->set_session_id("scripted");
    w->set_width(kSide);
    w->set_height(kSide);
    w->set_encoding(v1::ENCODING_H264);
    write(welcome);

    net::H264Settings settings;
    settings.width = settings.height = kSide;
    net::H264Encoder encoder(settings);
    int t = 0;
    encoder.encode(picture(t++), kSide, kSide);  // the keyframe the client never sees
    std::uint64_t sequence = 0;
    for (;;) {
      v1::ClientMessage m;
      try {
        if (!read(m)) throw std::runtime_error("a message that is not a ClientMessage");
      } catch (const beast::system_error& e) {
        if (e.code() == websocket::error::closed) return;  // the client is done
        throw;
      }
      if (!m.has_pose()) continue;
      log.poses.push_back(m.pose().sequence());
      if (m.pose().keyframe()) {
        log.keyframePoses.push_back(m.pose().sequence());
        encoder.requestKeyframe();
      }
      const net::H264AccessUnit unit = encoder.encode(picture(t++), kSide, kSide);
      log.sentKeyframe.push_back(unit.keyframe);
      v1::ServerMessage frame;
      auto* f = frame.mutable_frame();
      f->set_sequence(++sequence);
      f->set_pose_sequence(m.pose().sequence());
      f->set_width(kSide);
      f->set_height(kSide);
      f->set_encoding(v1::ENCODING_H264);
      f->set_data(unit.annexB);
      f->set_client_time_ms(m.pose().client_time_ms());
      write(frame);
    }
  } catch (const std::exception& e) {
    log.error = e.what();
  }
}

TEST(H264Session, AsksForAKeyframeWhenAFrameDoesNotDecodeAndDecodesFromThere) {
  asio::io_context serverIo;
  tcp::acceptor acceptor(serverIo, tcp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
  ServerLog log;
  std::thread server([&] { serveOneSession(acceptor, log); });

  constexpr std::uint64_t kPoses = 6;
  const PosePath path = PosePath::orbit(OrbitSweep{});
  SessionConfig config;
  config.url = parseWsUrl("ws://127.0.0.1:" + std::to_string(acceptor.local_endpoint().port()));
  config.hello.set_protocol_version(v1::PROTOCOL_VERSION_1);
  config.hello.set_width(kSide);
  config.hello.set_height(kSide);
  config.hello.set_encoding(v1::ENCODING_H264);
  config.hello.mutable_settings()->set_h264_bitrate_kbps(1500);
  config.hello.mutable_settings()->set_h264_keyframe_interval(90);
  config.path = &path;
  config.frames = kPoses;
  config.checkNotBlank = true;
  config.timeoutSeconds = 20;
  config.runStart = std::chrono::steady_clock::now();

  asio::io_context io;
  SessionStats stats;
  std::vector<std::string> messages;
  Session session(io, 0, config, stats, [](const FrameEvent&) {}, [&](const std::string& m) { messages.push_back(m); });
  session.start();
  io.run();
  server.join();

  ASSERT_EQ(log.error, "");
  EXPECT_EQ(stats.failure, "");
  EXPECT_EQ(log.hello.settings().h264_bitrate_kbps(), 1500u);
  EXPECT_EQ(log.hello.settings().h264_keyframe_interval(), 90u);
  // Pose 1's frame is the orphaned delta frame: pose 2 asks for a keyframe,
  // and only pose 2.
  ASSERT_EQ(log.sentKeyframe.size(), kPoses);
  EXPECT_FALSE(log.sentKeyframe[0]);
  EXPECT_EQ(log.keyframePoses, std::vector<std::uint64_t>{2});
  EXPECT_TRUE(log.sentKeyframe[1]);
  EXPECT_EQ(stats.undecodedFrames, 1u);
  EXPECT_EQ(stats.keyframeRequests, 1u);
  EXPECT_EQ(stats.frames, kPoses);
  EXPECT_EQ(stats.blankFrames, 0u);  // every frame from the keyframe on was decoded and checked
  ASSERT_FALSE(messages.empty());
  EXPECT_NE(messages.front().find("did not decode"), std::string::npos) << messages.front();
  EXPECT_NE(messages.front().find("keyframe"), std::string::npos) << messages.front();
}

}  // namespace
}  // namespace haarcast::client
