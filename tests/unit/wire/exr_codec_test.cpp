// EXR through the wire library: the renderer's floats round to half and no
// further, HDR values survive, and bad or mismatched payloads throw naming
// the codec.
#include "haarcast/wire/exr_codec.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace haarcast::wire {
namespace {

std::vector<float> testRgb(std::uint32_t w, std::uint32_t h) {
  std::vector<float> rgb(std::size_t{w} * h * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = 0.001f * static_cast<float>(i * i) + 0.5f;
  rgb[5] = 1000.0f;  // HDR values survive
  return rgb;
}

TEST(ExrCodec, RoundTripIsExactToHalf) {
  const std::vector<float> rgb = testRgb(17, 9);
  const LinearImage back = decodeExr(encodeExr(rgb, 17, 9));
  ASSERT_EQ(back.width, 17u);
  ASSERT_EQ(back.height, 9u);
  ASSERT_EQ(back.rgb.size(), rgb.size());
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    // Half has an 11-bit significand: relative error ≤ 2^-11.
    EXPECT_NEAR(back.rgb[i], rgb[i], std::abs(rgb[i]) * 0.00049f) << "at " << i;
  }
  EXPECT_EQ(back.rgb[5], 1000.0f);
}

TEST(ExrCodec, BadInputThrowsNamingTheCodec) {
  const std::vector<float> rgb = testRgb(4, 4);
  EXPECT_THROW(encodeExr(rgb, 4, 5), std::runtime_error);
  EXPECT_THROW(encodeExr(rgb, 0, 4), std::runtime_error);
  for (const std::string& bytes : {std::string("v/1\x01 garbage"), std::string(100, '\x07'), std::string()}) {
    try {
      decodeExr(bytes);
      ADD_FAILURE() << "decoded " << bytes.size() << " bytes of junk";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()).rfind("exr: ", 0), 0u) << e.what();
    }
  }
  const std::string exr = encodeExr(rgb, 4, 4);
  for (const std::size_t keep : {std::size_t{4}, exr.size() / 2, exr.size() - 1}) {
    EXPECT_THROW(decodeExr(exr.substr(0, keep)), std::runtime_error) << keep << " bytes";
  }
}

TEST(ExrCodec, TheDecoderRefusesAnotherSizeThanTheFrames) {
  const std::string exr = encodeExr(testRgb(6, 3), 6, 3);
  EXPECT_EQ(decodeExr(exr, ImageSize{6, 3}).rgb.size(), 6u * 3u * 3u);
  try {
    decodeExr(exr, ImageSize{3, 6});
    FAIL() << "a 6x3 EXR taken for 3x6";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("6x3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace haarcast::wire
