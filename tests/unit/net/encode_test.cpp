#include "haarcast/net/encode.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <gtest/gtest.h>

namespace haarcast::net {
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

TEST(Encode, RawIsTheBytes) {
  const auto rgba = testRgba(32, 16);
  const std::string raw = encodeRaw(rgba, 32, 16);
  ASSERT_EQ(raw.size(), rgba.size());
  EXPECT_EQ(0, std::memcmp(raw.data(), rgba.data(), raw.size()));
}

TEST(Encode, PngRoundTripIsExact) {
  const auto rgba = testRgba(48, 32);
  const std::string png = encodePng(rgba, 48, 32);
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  const Rgba8Image back = decodePng(png);
  EXPECT_EQ(back.width, 48);
  EXPECT_EQ(back.height, 32);
  EXPECT_EQ(back.rgba, rgba);
}

TEST(Encode, JpegRoundTripIsClose) {
  const auto rgba = testRgba(64, 64);
  const std::string jpeg = encodeJpeg(rgba, 64, 64, 95);
  const Rgba8Image back = decodeJpeg(jpeg);
  ASSERT_EQ(back.width, 64);
  ASSERT_EQ(back.height, 64);
  double sumAbs = 0;
  for (std::size_t i = 0; i < rgba.size(); ++i) sumAbs += std::abs(int(rgba[i]) - int(back.rgba[i]));
  EXPECT_LT(sumAbs / static_cast<double>(rgba.size()), 4.0);  // mean error in 8-bit levels at quality 95
  // Lower quality → fewer bytes (the quality setting reaches the codec).
  EXPECT_LT(encodeJpeg(rgba, 64, 64, 20).size(), jpeg.size());
}

TEST(Encode, ExrRoundTripIsExactToHalf) {
  io::RgbImage image = io::makeImage(17, 9);
  for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = 0.001f * static_cast<float>(i * i) + 0.5f;
  image.rgb[5] = 1000.0f;  // HDR values survive
  const io::RgbImage back = decodeExr(encodeExr(image));
  ASSERT_EQ(back.width, 17);
  ASSERT_EQ(back.height, 9);
  for (std::size_t i = 0; i < image.rgb.size(); ++i) {
    // Half has an 11-bit significand: relative error ≤ 2^-11.
    EXPECT_NEAR(back.rgb[i], image.rgb[i], std::abs(image.rgb[i]) * 0.00049f) << "at " << i;
  }
  EXPECT_EQ(back.rgb[5], 1000.0f);
}

TEST(Encode, BadInputThrowsNamingTheCodec) {
  const auto rgba = testRgba(8, 8);
  EXPECT_THROW(encodePng(rgba, 8, 9), std::runtime_error);
  EXPECT_THROW(encodeJpeg(rgba, 0, 8, 80), std::runtime_error);
  try {
    decodeJpeg("definitely not a jpeg");
    FAIL() << "no throw";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("jpeg"), std::string::npos) << e.what();
  }
  EXPECT_THROW(decodePng("\x89PNG garbage"), std::runtime_error);
  EXPECT_THROW(decodeExr("v/1\x01 garbage"), std::runtime_error);
  const std::string png = encodePng(rgba, 8, 8);
  EXPECT_THROW(decodePng(png.substr(0, png.size() / 2)), std::runtime_error);
}

}  // namespace
}  // namespace haarcast::net
