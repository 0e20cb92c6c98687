// The server's encodeFrame: the renderer's output handed to the wire
// library's encoders (their own tests: tests/unit/wire). Each 8-bit encoding
// gives the wire encoder's bytes for the RGBA8 image, EXR encodes the linear
// image, H.264 is refused (a session's H264Encoder encodes it), and bad
// sizes throw naming the codec.
#include "haarcast/net/encode.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "haarcast/wire/exr_codec.h"
#include "haarcast/wire/frame_codec.h"

namespace haarcast::net {
namespace {

std::vector<std::uint8_t> testRgba(int w, int h) {
  std::vector<std::uint8_t> rgba(static_cast<std::size_t>(w) * h * 4);
  for (std::size_t i = 0; i < rgba.size(); ++i) rgba[i] = static_cast<std::uint8_t>((i * 37) % 251);
  return rgba;
}

io::RgbImage testLinear(int w, int h) {
  io::RgbImage image = io::makeImage(w, h);
  for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = 0.01f * static_cast<float>(i) + 0.25f;
  return image;
}

TEST(EncodeFrame, EachEncodingIsTheWireEncodersBytes) {
  const auto rgba = testRgba(24, 16);
  const io::RgbImage linear = testLinear(24, 16);
  const io::RgbImage none;  // what an 8-bit encoding's frame may carry
  EXPECT_EQ(encodeFrame(FrameEncoding::Jpeg, rgba, 24, 16, none, 70), wire::encodeJpeg(rgba, 24, 16, 70));
  EXPECT_EQ(encodeFrame(FrameEncoding::Png, rgba, 24, 16, none, 70), wire::encodePng(rgba, 24, 16));
  EXPECT_EQ(encodeFrame(FrameEncoding::RawRgba8, rgba, 24, 16, none, 70), wire::encodeRaw(rgba, 24, 16));
  // EXR encodes the linear image, whatever the RGBA8 one holds.
  const std::string exr = encodeFrame(FrameEncoding::Exr, {}, 0, 0, linear, 70);
  EXPECT_EQ(exr, wire::encodeExr(linear.rgb, 24, 16));
  const wire::LinearImage back = wire::decodeExr(exr);
  EXPECT_EQ(back.width, 24u);
  EXPECT_EQ(back.height, 16u);
}

TEST(EncodeFrame, H264AndBadSizesAreRefused) {
  const auto rgba = testRgba(8, 8);
  EXPECT_THROW(encodeFrame(FrameEncoding::H264, rgba, 8, 8, {}, 85), std::logic_error);
  EXPECT_THROW(encodeFrame(FrameEncoding::Png, rgba, 8, 9, {}, 85), std::runtime_error);
  EXPECT_THROW(encodeFrame(FrameEncoding::Jpeg, rgba, -8, -8, {}, 85), std::runtime_error);
  try {
    encodeFrame(FrameEncoding::Exr, rgba, 8, 8, {}, 85);  // no linear image
    FAIL() << "EXR encoded without a linear image";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("exr: ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace haarcast::net
