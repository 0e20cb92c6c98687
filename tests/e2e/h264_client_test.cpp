// The H.264 path end to end without sockets: the server's session encoder
// (haarcast_net's H264Encoder) → Annex-B access units → the CLI client's
// FrameDecoder, on a rendered-like sequence (a shaded disc orbiting over a
// sky gradient, 60 frames at 256²). Every frame decodes, is not blank, and is
// within 30 dB PSNR of its source; the stream costs well under JPEG q85 of
// the same frames; a client joining at a requested keyframe decodes from
// there; one joining between keyframes gets an error, not a picture.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "haarcast/client/frame_image.h"
#include "haarcast/net/h264_encoder.h"
#include "haarcast/net/protocol.h"
#include "haarcast/wire/frame_codec.h"
#include "haarcast/wire/frame_decode.h"

namespace haarcast::client {
namespace {

constexpr int kSide = 256;
constexpr int kFrames = 60;
const int kJpegQuality = net::Defaults{}.jpegQuality;  // the server's default (85)
constexpr double kMinPsnrDb = 30.0;
constexpr double kMaxBytesRatioToJpeg = 0.5;  // "well below": at most half

// Frame t of the sequence: a warm-to-blue sky gradient that drifts, and a
// Lambert-shaded disc (light from the upper left) on a circle around the
// centre, like an object turning in front of the environment.
std::vector<std::uint8_t> orbitFrame(int t) {
  std::vector<std::uint8_t> rgba(std::size_t(kSide) * kSide * 4);
  const double angle = 2.0 * M_PI * t / kFrames;
  const double cx = kSide * (0.5 + 0.25 * std::cos(angle)), cy = kSide * (0.5 + 0.25 * std::sin(angle));
  const double radius = kSide * 0.18;
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      std::uint8_t* p = &rgba[(std::size_t(y) * kSide + x) * 4];
      const double v = static_cast<double>(y) / kSide, drift = 0.1 * std::sin(angle + x * 0.01);
      double r = 200 - 120 * v + 20 * drift, g = 170 - 60 * v, b = 110 + 120 * v - 20 * drift;
      const double dx = (x - cx) / radius, dy = (y - cy) / radius, d2 = dx * dx + dy * dy;
      if (d2 < 1.0) {
        const double nz = std::sqrt(1.0 - d2);
        const double lambert = std::max(0.0, (-dx - dy + nz) / std::sqrt(3.0));
        r = 30 + 210 * lambert;
        g = 40 + 120 * lambert;
        b = 35 + 60 * lambert;
      }
      p[0] = static_cast<std::uint8_t>(std::lround(std::clamp(r, 0.0, 255.0)));
      p[1] = static_cast<std::uint8_t>(std::lround(std::clamp(g, 0.0, 255.0)));
      p[2] = static_cast<std::uint8_t>(std::lround(std::clamp(b, 0.0, 255.0)));
      p[3] = 255;
    }
  }
  return rgba;
}

// Peak signal-to-noise ratio of R, G and B (alpha ignored), in dB.
double psnrDb(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (i % 4 == 3) continue;
    const double d = static_cast<double>(a[i]) - static_cast<double>(b[i]);
    sum += d * d;
    ++n;
  }
  const double mse = sum / static_cast<double>(n);
  return mse == 0.0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / mse);
}

std::span<const std::uint8_t> bytesOf(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

struct Stream {
  std::vector<std::vector<std::uint8_t>> sources;
  std::vector<net::H264AccessUnit> units;
};

// The sequence at the server's default H.264 settings, with a keyframe
// requested before frame `keyframeAt` (as PoseUpdate.keyframe does).
Stream encodeOrbit(int keyframeAt) {
  net::H264Settings settings;
  settings.width = kSide;
  settings.height = kSide;
  net::H264Encoder encoder(settings);
  Stream s;
  for (int t = 0; t < kFrames; ++t) {
    s.sources.push_back(orbitFrame(t));
    if (t == keyframeAt) encoder.requestKeyframe();
    s.units.push_back(encoder.encode(s.sources.back(), kSide, kSide));
  }
  return s;
}

TEST(H264Client, DecodesEveryFrameOfTheOrbitCloseToItsSource) {
  const Stream s = encodeOrbit(30);
  FrameDecoder decoder;
  std::size_t h264Bytes = 0, jpegBytes = 0;
  double worstPsnr = 99.0;
  for (int t = 0; t < kFrames; ++t) {
    const wire::Rgba8Image image = decoder.decode(v1::ENCODING_H264, bytesOf(s.units[t].annexB), kSide, kSide);
    ASSERT_EQ(image.pixels.size(), s.sources[t].size());
    EXPECT_FALSE(isBlank(pixelStats(image))) << "frame " << t;
    const double psnr = psnrDb(image.pixels, s.sources[t]);
    EXPECT_GE(psnr, kMinPsnrDb) << "frame " << t;
    worstPsnr = std::min(worstPsnr, psnr);
    h264Bytes += s.units[t].annexB.size();
    jpegBytes += wire::encodeJpeg(s.sources[t], kSide, kSide, kJpegQuality).size();
  }
  const double ratio = static_cast<double>(h264Bytes) / static_cast<double>(jpegBytes);
  std::printf("H.264 %.0f B/frame, JPEG q%d %.0f B/frame: ratio %.3f; worst PSNR %.1f dB\n",
              static_cast<double>(h264Bytes) / kFrames, kJpegQuality, static_cast<double>(jpegBytes) / kFrames,
              ratio, worstPsnr);
  EXPECT_LT(ratio, kMaxBytesRatioToJpeg);
}

TEST(H264Client, AClientJoiningAtARequestedKeyframeDecodesFromThere) {
  const Stream s = encodeOrbit(30);
  ASSERT_TRUE(s.units[30].keyframe);
  FrameDecoder late;
  for (int t = 30; t < kFrames; ++t) {
    const wire::Rgba8Image image = late.decode(v1::ENCODING_H264, bytesOf(s.units[t].annexB), kSide, kSide);
    EXPECT_GE(psnrDb(image.pixels, s.sources[t]), kMinPsnrDb) << "frame " << t;
  }

  // Between keyframes there is nothing to start from: an error that says
  // how to recover, never a grey picture.
  FrameDecoder between;
  try {
    between.decode(v1::ENCODING_H264, bytesOf(s.units[31].annexB), kSide, kSide);
    FAIL() << "a delta frame decoded without its keyframe";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("keyframe"), std::string::npos) << e.what();
  }
}

TEST(H264Client, RefusesH264OutsideASessionAndFramesOfAnotherSize) {
  const Stream s = encodeOrbit(-1);
  EXPECT_THROW(wire::decodeFrame(v1::ENCODING_H264, s.units[0].annexB, kSide, kSide), std::runtime_error);
  FrameDecoder decoder;
  EXPECT_THROW(decoder.decode(v1::ENCODING_H264, bytesOf(s.units[0].annexB), kSide, kSide / 2), std::runtime_error);
  const std::vector<std::uint8_t> junk(100, 0x42);
  FrameDecoder fresh;
  EXPECT_THROW(fresh.decode(v1::ENCODING_H264, junk, kSide, kSide), std::runtime_error);
}

TEST(H264Client, DecodedFramesAreWrittenAsPng) {
  const wire::Rgba8Image image{kSide, kSide, orbitFrame(7)};
  const std::string png = wire::encodePng(image.pixels, image.width, image.height);
  const wire::Rgba8Image back = wire::decodeFrame(v1::ENCODING_PNG, png, kSide, kSide);
  EXPECT_EQ(back.pixels, image.pixels);
}

// Not a check of its own: writes the orbit's stream for the browser's
// WebCodecs check (h264_webcodecs.mjs, run by run_h264_webcodecs.sh) when
// HAARCAST_H264_STREAM_DIR names a folder: orbit.h264 (the access units
// back to back), orbit.json (each unit's offset, size and keyframe flag) and
// the last source frame as raw RGBA8, which the browser's picture must match.
TEST(H264Client, WritesTheOrbitForTheBrowserCheck) {
  const char* dir = std::getenv("HAARCAST_H264_STREAM_DIR");
  if (!dir) GTEST_SKIP() << "HAARCAST_H264_STREAM_DIR is not set";
  const Stream s = encodeOrbit(30);
  const std::filesystem::path out(dir);
  std::filesystem::create_directories(out);
  std::ofstream stream(out / "orbit.h264", std::ios::binary);
  std::ofstream index(out / "orbit.json");
  index << "{\"width\": " << kSide << ", \"height\": " << kSide << ", \"min_psnr_db\": " << kMinPsnrDb
        << ", \"units\": [";
  std::size_t offset = 0;
  for (std::size_t i = 0; i < s.units.size(); ++i) {
    const std::string& au = s.units[i].annexB;
    stream.write(au.data(), static_cast<std::streamsize>(au.size()));
    index << (i ? ", " : "") << "{\"offset\": " << offset << ", \"size\": " << au.size()
          << ", \"key\": " << (s.units[i].keyframe ? "true" : "false") << "}";
    offset += au.size();
  }
  index << "]}\n";
  std::ofstream last(out / "last-source.rgba", std::ios::binary);
  last.write(reinterpret_cast<const char*>(s.sources.back().data()),
             static_cast<std::streamsize>(s.sources.back().size()));
  ASSERT_TRUE(stream && index && last) << "cannot write under " << out;
}

}  // namespace
}  // namespace haarcast::client
