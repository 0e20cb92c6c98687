// The 8-bit codecs of the wire library both ways: RAW is the bytes, PNG is
// lossless, JPEG close and smaller at lower quality; bad input throws naming
// the codec, and a decoder given the Frame's size refuses another one.
#include "haarcast/wire/frame_codec.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace haarcast::wire {
namespace {

// A smooth colour gradient with a sharp square: JPEG keeps the first well
// and the test sees whether rows or channels are swapped.
std::vector<std::uint8_t> testRgba(int w, int h) {
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w) * h * 4);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      auto* p = &rgba[(static_cast<std::size_t>(y) * w + x) * 4];
      p[0] = static_cast<std::uint8_t>(255 * x / (w - 1));
      p[1] = static_cast<std::uint8_t>(255 * y / (h - 1));
      p[2] = (x > w / 4 && x < w / 2 && y > h / 4 && y < h / 2) ? 255 : 40;
      p[3] = 255;
    }
  }
  return rgba;
}

// The message of what `f` throws as std::runtime_error; a failure if nothing.
template <typename F>
std::string thrown(F&& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no std::runtime_error";
  return {};
}

TEST(FrameCodec, RawIsTheBytes) {
  const auto rgba = testRgba(32, 16);
  const std::string raw = encodeRaw(rgba, 32, 16);
  ASSERT_EQ(raw.size(), rgba.size());
  EXPECT_EQ(0, std::memcmp(raw.data(), rgba.data(), raw.size()));
  const Rgba8Image back = decodeRaw(raw, {32, 16});
  EXPECT_EQ(back.width, 32u);
  EXPECT_EQ(back.height, 16u);
  EXPECT_EQ(back.pixels, rgba);
}

TEST(FrameCodec, PngRoundTripIsExact) {
  const auto rgba = testRgba(48, 32);
  const std::string png = encodePng(rgba, 48, 32);
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  const Rgba8Image back = decodePng(png);
  EXPECT_EQ(back.width, 48u);
  EXPECT_EQ(back.height, 32u);
  EXPECT_EQ(back.pixels, rgba);
}

TEST(FrameCodec, JpegRoundTripIsClose) {
  const auto rgba = testRgba(64, 64);
  const std::string jpeg = encodeJpeg(rgba, 64, 64, 95);
  const Rgba8Image back = decodeJpeg(jpeg);
  ASSERT_EQ(back.width, 64u);
  ASSERT_EQ(back.height, 64u);
  double sumAbs = 0;
  for (std::size_t i = 0; i < rgba.size(); ++i) sumAbs += std::abs(int(rgba[i]) - int(back.pixels[i]));
  EXPECT_LT(sumAbs / static_cast<double>(rgba.size()), 4.0);  // mean error in 8-bit levels at quality 95
  // Lower quality → fewer bytes (the quality setting reaches the codec).
  EXPECT_LT(encodeJpeg(rgba, 64, 64, 20).size(), jpeg.size());
  // Out of range qualities are clamped, not refused.
  EXPECT_EQ(encodeJpeg(rgba, 64, 64, 400), encodeJpeg(rgba, 64, 64, 100));
  EXPECT_EQ(encodeJpeg(rgba, 64, 64, -3), encodeJpeg(rgba, 64, 64, 1));
}

TEST(FrameCodec, BadInputThrowsNamingTheCodec) {
  const auto rgba = testRgba(8, 8);
  EXPECT_THROW(encodePng(rgba, 8, 9), std::runtime_error);
  EXPECT_THROW(encodeJpeg(rgba, 0, 8, 80), std::runtime_error);
  EXPECT_THROW(encodeRaw(rgba, 8, 7), std::runtime_error);
  EXPECT_NE(thrown([] { decodeJpeg("definitely not a jpeg"); }).find("jpeg"), std::string::npos);
  EXPECT_NE(thrown([] { decodeJpeg(""); }).find("jpeg"), std::string::npos);
  EXPECT_NE(thrown([] { decodePng("\x89PNG garbage"); }).find("png"), std::string::npos);
  EXPECT_NE(thrown([] { decodePng(""); }).find("png"), std::string::npos);
  const std::string png = encodePng(rgba, 8, 8);
  EXPECT_THROW(decodePng(png.substr(0, png.size() / 2)), std::runtime_error);
  const std::string jpeg = encodeJpeg(rgba, 8, 8, 80);
  EXPECT_THROW(decodeJpeg(jpeg.substr(0, 20)), std::runtime_error);
  // Each decoder on the others' bytes.
  EXPECT_THROW(decodeJpeg(png), std::runtime_error);
  EXPECT_THROW(decodePng(jpeg), std::runtime_error);
}

TEST(FrameCodec, ADecoderRefusesAnotherSizeThanTheFramesBeforeDecoding) {
  const auto rgba = testRgba(16, 12);
  const std::string png = encodePng(rgba, 16, 12), jpeg = encodeJpeg(rgba, 16, 12, 90), raw = encodeRaw(rgba, 16, 12);
  EXPECT_EQ(decodePng(png, ImageSize{16, 12}).pixels, rgba);
  EXPECT_EQ(decodeJpeg(jpeg, ImageSize{16, 12}).width, 16u);
  const std::string message = thrown([&] { decodePng(png, ImageSize{16, 13}); });
  EXPECT_NE(message.find("png"), std::string::npos) << message;
  EXPECT_NE(message.find("16x12"), std::string::npos) << message;  // both sizes named
  EXPECT_NE(message.find("16x13"), std::string::npos) << message;
  EXPECT_THROW(decodeJpeg(jpeg, ImageSize{12, 16}), std::runtime_error);
  EXPECT_THROW(decodeRaw(raw, {16, 13}), std::runtime_error);
  EXPECT_THROW(decodeRaw(raw.substr(1), {16, 12}), std::runtime_error);
  EXPECT_THROW(decodeRaw(raw, {0, 12}), std::runtime_error);
}

}  // namespace
}  // namespace haarcast::wire
