// The session H.264 encoder's stream structure: keyframes where the protocol
// promises them (first frame, interval, request, restart), SPS and PPS before
// each, one access unit per frame, and settings refused with their range.
// Decoding and picture quality: tests/e2e/h264_client_test.cpp.
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "haarcast/net/h264_encoder.h"

namespace haarcast::net {
namespace {

constexpr int kNalSlice = 1, kNalIdr = 5, kNalSps = 7, kNalPps = 8;

// A frame that changes every time: a diagonal ramp sliding by 3 pixels per
// frame, so every frame has something to code.
std::vector<std::uint8_t> slidingRamp(int width, int height, int t) {
  std::vector<std::uint8_t> rgba(std::size_t(width) * height * 4);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      std::uint8_t* p = &rgba[(std::size_t(y) * width + x) * 4];
      p[0] = static_cast<std::uint8_t>((x + 3 * t) & 255);
      p[1] = static_cast<std::uint8_t>((y * 2) & 255);
      p[2] = static_cast<std::uint8_t>((x + y + t) & 255);
      p[3] = 255;
    }
  }
  return rgba;
}

bool has(const std::vector<int>& types, int type) {
  for (const int t : types) {
    if (t == type) return true;
  }
  return false;
}

// A keyframe as a joining client needs it: SPS, then PPS, then the IDR slice.
void expectSelfContainedKeyframe(const H264AccessUnit& au) {
  EXPECT_TRUE(au.keyframe) << "frame " << au.index;
  const std::vector<int> types = h264NalTypes(au.annexB);
  std::size_t sps = types.size(), pps = types.size(), idr = types.size();
  for (std::size_t i = 0; i < types.size(); ++i) {
    if (types[i] == kNalSps && sps == types.size()) sps = i;
    if (types[i] == kNalPps && pps == types.size()) pps = i;
    if (types[i] == kNalIdr && idr == types.size()) idr = i;
  }
  ASSERT_LT(sps, types.size()) << "frame " << au.index << ": no SPS before the keyframe";
  ASSERT_LT(pps, types.size()) << "frame " << au.index << ": no PPS before the keyframe";
  ASSERT_LT(idr, types.size()) << "frame " << au.index << ": no IDR slice";
  EXPECT_LT(sps, idr);
  EXPECT_LT(pps, idr);
}

void expectDelta(const H264AccessUnit& au) {
  EXPECT_FALSE(au.keyframe) << "frame " << au.index;
  const std::vector<int> types = h264NalTypes(au.annexB);
  EXPECT_TRUE(has(types, kNalSlice)) << "frame " << au.index;
  EXPECT_FALSE(has(types, kNalIdr)) << "frame " << au.index;
}

H264Settings settings(int w, int h) {
  H264Settings s;
  s.width = w;
  s.height = h;
  return s;
}

TEST(H264Encoder, KeyframesAtTheStartAtTheIntervalAndOnRequest) {
  H264Settings s = settings(64, 48);
  s.keyframeInterval = 10;
  H264Encoder encoder(s);
  for (int t = 0; t < 25; ++t) {
    if (t == 4) encoder.requestKeyframe();
    const H264AccessUnit au = encoder.encode(slidingRamp(64, 48, t), 64, 48);
    // One access unit per frame in, numbered as sent: none held back.
    EXPECT_EQ(au.index, t);
    ASSERT_FALSE(au.annexB.empty()) << "frame " << t;
    // x264 counts the interval from the last keyframe, requested or not.
    const bool key = t == 0 || t == 4 || t == 14 || t == 24;
    if (key) {
      expectSelfContainedKeyframe(au);
    } else {
      expectDelta(au);
    }
  }
}

TEST(H264Encoder, RestartsWithAKeyframeOnResizeAndNewSettings) {
  H264Encoder encoder(settings(64, 48));
  expectSelfContainedKeyframe(encoder.encode(slidingRamp(64, 48, 0), 64, 48));
  expectDelta(encoder.encode(slidingRamp(64, 48, 1), 64, 48));

  const H264AccessUnit resized = encoder.encode(slidingRamp(96, 64, 2), 96, 64);
  expectSelfContainedKeyframe(resized);
  EXPECT_EQ(resized.index, 0);  // a new stream
  EXPECT_EQ(encoder.settings().width, 96);
  expectDelta(encoder.encode(slidingRamp(96, 64, 3), 96, 64));

  H264Settings same = encoder.settings();
  encoder.reconfigure(same);  // nothing changes: the stream goes on
  expectDelta(encoder.encode(slidingRamp(96, 64, 4), 96, 64));

  H264Settings lower = same;
  lower.bitrateKbps = 500;
  encoder.reconfigure(lower);
  expectSelfContainedKeyframe(encoder.encode(slidingRamp(96, 64, 5), 96, 64));
}

TEST(H264Encoder, TheBitrateCapBoundsTheStream) {
  // Noise-like content at a low cap: the bytes over 30 frames stay near the
  // cap's one second (VBV), where uncapped CRF would spend several times it.
  const int w = 256, h = 256, frames = 30;
  H264Settings s = settings(w, h);
  s.bitrateKbps = 300;
  s.fps = 30.0;
  H264Encoder capped(s);
  std::size_t bytes = 0;
  std::uint32_t seed = 1;
  std::vector<std::uint8_t> rgba(std::size_t(w) * h * 4, 255);
  for (int t = 0; t < frames; ++t) {
    for (std::size_t i = 0; i < rgba.size(); ++i) {
      seed = seed * 1664525u + 1013904223u;  // Numerical Recipes' LCG
      if (i % 4 != 3) rgba[i] = static_cast<std::uint8_t>(seed >> 24);
    }
    bytes += capped.encode(rgba, w, h).annexB.size();
  }
  const double kbits = static_cast<double>(bytes) * 8.0 / 1000.0;
  // One second at the cap plus the one-second buffer it may start full with.
  EXPECT_LT(kbits, 2.0 * s.bitrateKbps) << bytes << " bytes in " << frames << " frames";
}

TEST(H264Encoder, RefusesOddSizesAndSettingsOutsideTheirRanges) {
  const auto message = [](const H264Settings& s) {
    try {
      validateH264Settings(s);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message(settings(65, 48)).find("even width and height"), std::string::npos) << message(settings(65, 48));
  EXPECT_NE(message(settings(0, 48)).find("width"), std::string::npos);
  H264Settings s = settings(64, 48);
  s.bitrateKbps = 1;
  const std::string range = std::to_string(kMinH264BitrateKbps) + ".." + std::to_string(kMaxH264BitrateKbps);
  EXPECT_NE(message(s).find("bitrate (kbit/s) 1 is outside " + range), std::string::npos) << message(s);
  s = settings(64, 48);
  s.keyframeInterval = 0;
  EXPECT_NE(message(s).find("keyframe interval"), std::string::npos) << message(s);
  s = settings(64, 48);
  s.preset = "warp-speed";
  EXPECT_THROW(H264Encoder{s}, std::runtime_error);  // names avcodec_open2 and the preset

  H264Encoder encoder(settings(64, 48));
  EXPECT_THROW(encoder.encode(slidingRamp(63, 48, 0), 63, 48), std::invalid_argument);
  EXPECT_THROW(encoder.encode(std::vector<std::uint8_t>(10), 64, 48), std::invalid_argument);
}

TEST(H264Encoder, NalTypesReadsStartCodesOfBothLengths) {
  const std::string annexB("\x00\x00\x00\x01\x67\xAA\x00\x00\x01\x68\xBB\x00\x00\x01\x65", 15);
  EXPECT_EQ(h264NalTypes(annexB), (std::vector<int>{kNalSps, kNalPps, kNalIdr}));
  EXPECT_TRUE(h264NalTypes("").empty());
}

}  // namespace
}  // namespace haarcast::net
