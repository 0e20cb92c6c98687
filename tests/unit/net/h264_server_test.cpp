// ENCODING_H264 over a real socket (issue 13): every frame decodes through
// the CLI client's decoder in order, the first is a keyframe (SPS, PPS and
// an IDR), later ones are not unless asked, and a PoseUpdate with `keyframe`
// gets a keyframe for the frame answering it. Bad H.264 Hellos are refused
// with the code and range named.
#include <algorithm>
#include <span>

#include "haarcast/client/frame_image.h"
#include "haarcast/net/h264_encoder.h"
#include "server_fixture.h"

namespace haarcast::net::test {
namespace {

bool isKeyframe(const std::string& annexB) {
  const auto types = h264NalTypes(annexB);
  return std::find(types.begin(), types.end(), 5) != types.end() &&
         std::find(types.begin(), types.end(), 7) != types.end() &&
         std::find(types.begin(), types.end(), 8) != types.end();
}

TEST(ServerH264, FramesDecodeInOrderAndAKeyframePoseGetsAKeyframe) {
  TestServer server;
  Client c(server.port());
  auto h = hello(64, 48, v1::ENCODING_H264, 60);
  h.mutable_hello()->mutable_settings()->set_h264_keyframe_interval(1000);  // no periodic IDR within the test
  const v1::Welcome welcome = c.handshake(h);
  EXPECT_EQ(welcome.limits().max_h264_bitrate_kbps(), static_cast<std::uint32_t>(kMaxH264BitrateKbps));

  client::FrameDecoder decoder;
  std::vector<bool> keyframes;
  std::uint64_t keyframePose = 0;
  for (std::uint64_t sequence = 1; sequence <= 12; ++sequence) {
    v1::ClientMessage m = pose(sequence, 10.0 * static_cast<double>(sequence));
    if (sequence == 8) {
      // Only sequence + keyframe: a keyframe of the same view.
      m = v1::ClientMessage{};
      m.mutable_pose()->set_sequence(sequence);
      m.mutable_pose()->set_keyframe(true);
      keyframePose = sequence;
    }
    c.send(m);
    // Frames until the one answering this pose (the first frame answers
    // the scene's own view, pose 0).
    for (;;) {
      auto f = c.expect(v1::ServerMessage::kFrame, 30s);
      ASSERT_TRUE(f) << "no frame for pose " << sequence;
      const auto& frame = f->frame();
      EXPECT_EQ(frame.encoding(), v1::ENCODING_H264);
      EXPECT_EQ(frame.settings().h264_keyframe_interval(), 1000u);
      const std::string& data = frame.data();
      const wire::Rgba8Image image = decoder.decode(
          v1::ENCODING_H264, std::span(reinterpret_cast<const std::uint8_t*>(data.data()), data.size()), frame.width(),
          frame.height());
      EXPECT_EQ(image.width, 64u);
      EXPECT_EQ(image.height, 48u);
      EXPECT_FALSE(client::isBlank(client::pixelStats(image))) << "frame " << frame.sequence() << " decoded blank";
      keyframes.push_back(isKeyframe(data));
      if (frame.pose_sequence() == keyframePose && keyframePose != 0) {
        EXPECT_TRUE(keyframes.back()) << "keyframe pose";
      }
      if (frame.pose_sequence() >= sequence) break;
    }
  }
  ASSERT_GE(keyframes.size(), 12u);
  EXPECT_TRUE(keyframes.front()) << "the first frame is not a keyframe";
  // Besides the first and the asked-for one, none: each frame needs the ones
  // before it, which is what makes the stream cheaper than JPEG.
  EXPECT_EQ(std::count(keyframes.begin(), keyframes.end(), true), 2);
}

TEST(ServerH264, OddSizeAndOutOfRangeSettingsAreRefused) {
  TestServer server;
  {
    Client c(server.port());
    c.send(hello(63, 48, v1::ENCODING_H264));
    const auto e = c.expectError(v1::ERROR_CODE_BAD_RESOLUTION, true);
    EXPECT_NE(e.message().find("even"), std::string::npos) << e.message();
  }
  {
    Client c(server.port());
    auto h = hello(64, 48, v1::ENCODING_H264);
    h.mutable_hello()->mutable_settings()->set_h264_bitrate_kbps(kMaxH264BitrateKbps + 1);
    c.send(h);
    const auto e = c.expectError(v1::ERROR_CODE_BAD_SETTINGS, true);
    EXPECT_NE(e.message().find(std::to_string(kMaxH264BitrateKbps)), std::string::npos) << e.message();
  }
}

}  // namespace
}  // namespace haarcast::net::test
