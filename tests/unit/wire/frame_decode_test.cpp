// A Frame's payload back to pixels (decodeFrame), on payloads written with
// the image libraries directly: every encoding, EXR shown as sRGB, and each
// payload that does not match its Frame refused.
#include "haarcast/wire/frame_decode.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <ImfRgbaFile.h>
#include <gtest/gtest.h>
#include <png.h>
#include <turbojpeg.h>

namespace haarcast::wire {
namespace {

Rgba8Image gradient(std::uint32_t w, std::uint32_t h) {
  Rgba8Image img{w, h, std::vector<std::uint8_t>(std::size_t{w} * h * 4)};
  for (std::uint32_t y = 0; y < h; ++y) {
    for (std::uint32_t x = 0; x < w; ++x) {
      std::uint8_t* p = &img.pixels[(std::size_t{y} * w + x) * 4];
      p[0] = static_cast<std::uint8_t>(x * 255 / (w - 1));
      p[1] = static_cast<std::uint8_t>(y * 255 / (h - 1));
      p[2] = 64;
      p[3] = 255;
    }
  }
  return img;
}

std::string toPng(const Rgba8Image& img) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = img.width;
  image.height = img.height;
  image.format = PNG_FORMAT_RGBA;
  png_alloc_size_t size = 0;
  EXPECT_TRUE(png_image_write_to_memory(&image, nullptr, &size, 0, img.pixels.data(), 0, nullptr));
  std::string out(size, '\0');
  EXPECT_TRUE(png_image_write_to_memory(&image, out.data(), &size, 0, img.pixels.data(), 0, nullptr));
  out.resize(size);
  return out;
}

std::string toJpeg(const Rgba8Image& img) {
  tjhandle tj = tjInitCompress();
  unsigned char* buf = nullptr;
  unsigned long size = 0;
  EXPECT_EQ(tjCompress2(tj, img.pixels.data(), static_cast<int>(img.width), 0, static_cast<int>(img.height), TJPF_RGBA,
                        &buf, &size, TJSAMP_420, 90, 0),
            0);
  std::string out(reinterpret_cast<const char*>(buf), size);
  tjFree(buf);
  tjDestroy(tj);
  return out;
}

std::string bytesOf(const std::vector<std::uint8_t>& v) { return std::string(v.begin(), v.end()); }

TEST(FrameDecode, DecodesEveryEncodingBackToThePixels) {
  const Rgba8Image img = gradient(64, 48);
  const auto png = toPng(img);
  const Rgba8Image fromPng = decodeFrame(v1::ENCODING_PNG, png, 64, 48);
  EXPECT_EQ(fromPng.pixels, img.pixels);  // lossless
  const Rgba8Image fromRaw = decodeFrame(v1::ENCODING_RAW_RGBA8, bytesOf(img.pixels), 64, 48);
  EXPECT_EQ(fromRaw.pixels, img.pixels);
  const auto jpeg = toJpeg(img);
  const Rgba8Image fromJpeg = decodeFrame(v1::ENCODING_JPEG, jpeg, 64, 48);
  ASSERT_EQ(fromJpeg.pixels.size(), img.pixels.size());
  double maxError = 0;
  for (std::size_t i = 0; i < img.pixels.size(); ++i) {
    maxError = std::max(maxError, std::abs(double(fromJpeg.pixels[i]) - double(img.pixels[i])));
  }
  EXPECT_LT(maxError, 24.0) << "JPEG q90 of a smooth gradient stays close";
}

TEST(FrameDecode, DecodesExrToSrgb) {
  // A linear half-float EXR: left half 0.0, right half 1.0 → sRGB 0 and 255.
  const auto path = std::filesystem::temp_directory_path() / "haarcast_wire_test.exr";
  {
    std::vector<Imf::Rgba> pixels(8 * 4);
    for (int y = 0; y < 4; ++y) {
      for (int x = 0; x < 8; ++x) pixels[static_cast<std::size_t>(y * 8 + x)] = Imf::Rgba(x < 4 ? 0.f : 1.f, 0.18f, 0.f, 1.f);
    }
    Imf::RgbaOutputFile out(path.c_str(), 8, 4, Imf::WRITE_RGBA);
    out.setFrameBuffer(pixels.data(), 1, 8);
    out.writePixels(4);
  }
  std::ostringstream read;
  read << std::ifstream(path, std::ios::binary).rdbuf();
  const std::string bytes = read.str();
  std::filesystem::remove(path);
  const Rgba8Image img = decodeFrame(v1::ENCODING_EXR, bytes, 8, 4);
  EXPECT_EQ(img.pixels[0], 0);
  EXPECT_EQ(img.pixels[7 * 4], 255);
  EXPECT_NEAR(img.pixels[1], 118, 1) << "linear 0.18 is sRGB 118";
  EXPECT_THROW(decodeFrame(v1::ENCODING_EXR, bytes, 4, 8), std::runtime_error);
}

TEST(FrameDecode, RejectsPayloadsThatDoNotMatchTheFrame) {
  const Rgba8Image img = gradient(16, 16);
  const auto png = toPng(img);
  EXPECT_THROW(decodeFrame(v1::ENCODING_PNG, png, 16, 17), std::runtime_error);  // size mismatch
  EXPECT_THROW(decodeFrame(v1::ENCODING_RAW_RGBA8, png, 16, 16), std::runtime_error);
  const auto jpeg = toJpeg(img);
  EXPECT_THROW(decodeFrame(v1::ENCODING_JPEG, jpeg, 17, 16), std::runtime_error);  // size mismatch
  const std::string truncated = jpeg.substr(0, 20);
  EXPECT_THROW(decodeFrame(v1::ENCODING_JPEG, truncated, 16, 16), std::runtime_error);
  const std::string junk(100, 7);
  EXPECT_THROW(decodeFrame(v1::ENCODING_EXR, junk, 16, 16), std::runtime_error);
  EXPECT_THROW(decodeFrame(v1::ENCODING_UNSPECIFIED, junk, 16, 16), std::runtime_error);
  EXPECT_THROW(decodeFrame(static_cast<v1::Encoding>(99), junk, 16, 16), std::runtime_error);
  EXPECT_THROW(decodeFrame(v1::ENCODING_PNG, png, 0, 16), std::runtime_error);  // a Frame with no size
  // Each decoder on every other encoding's bytes.
  for (const auto e : {v1::ENCODING_JPEG, v1::ENCODING_PNG, v1::ENCODING_EXR}) {
    for (const std::string& payload : {png, jpeg, junk}) {
      if ((e == v1::ENCODING_PNG && payload == png) || (e == v1::ENCODING_JPEG && payload == jpeg)) continue;
      EXPECT_THROW(decodeFrame(e, payload, 16, 16), std::runtime_error) << v1::Encoding_Name(e);
    }
  }
}

TEST(FrameDecode, H264IsRefusedOutsideASession) {
  try {
    decodeFrame(v1::ENCODING_H264, std::string(64, '\0'), 16, 16);
    FAIL() << "an H.264 frame decoded alone";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("FrameDecoder"), std::string::npos) << e.what();
  }
}

TEST(FrameDecode, LinearToSrgbFollowsTheStandardCurve) {
  EXPECT_EQ(linearToSrgb8(-1.0f), 0);
  EXPECT_EQ(linearToSrgb8(0.0f), 0);
  EXPECT_EQ(linearToSrgb8(0.0015654f), 5);  // on the linear toe: 12.92 · v · 255 = 5.16
  EXPECT_EQ(linearToSrgb8(std::nanf("")), 0);  // a NaN in a hostile EXR shows black
  EXPECT_EQ(linearToSrgb8(0.18f), 118);
  EXPECT_EQ(linearToSrgb8(1.0f), 255);
  EXPECT_EQ(linearToSrgb8(7.0f), 255);
}

}  // namespace
}  // namespace haarcast::wire
