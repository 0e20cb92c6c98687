#include "haarcast/io/image.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

namespace haarcast::io {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<std::uint8_t>;

// A fresh directory per test, removed afterwards.
class ImageIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("haarcast_image_test_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
            "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

void writeBytes(const std::string& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

Bytes readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void append(Bytes& b, const std::string& s) { b.insert(b.end(), s.begin(), s.end()); }

RgbImage randomImage(int width, int height, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  RgbImage img = makeImage(width, height);
  // Dynamic range like a real probe: most values small, a few huge, some negative.
  for (float& v : img.rgb) v = u(rng) < 0.05f ? 1e4f * u(rng) : u(rng) - 0.1f;
  return img;
}

// Runs `read` and checks it throws std::runtime_error naming `path` and
// containing `what`.
void expectFailure(const std::function<void()>& read, const std::string& path, const std::string& what) {
  try {
    read();
    ADD_FAILURE() << "no exception for " << path;
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(path), std::string::npos) << message;
    EXPECT_NE(message.find(what), std::string::npos) << "expected \"" << what << "\" in: " << message;
  }
}

// Ward's decoding, (m + ½)·2^(e − 136), spelled out independently of the reader.
float rgbeValue(std::uint8_t mantissa, std::uint8_t exponent) {
  return exponent == 0 ? 0.0f : static_cast<float>((mantissa + 0.5) * std::pow(2.0, exponent - 136.0));
}

// A width-10 image's RGBE pixels: in every channel the first six are equal and
// the last four differ, so new-style RLE encodes each channel as one run of 6
// and one literal of 4.
std::vector<std::array<std::uint8_t, 4>> rlePixels() {
  std::vector<std::array<std::uint8_t, 4>> px(10);
  for (int x = 0; x < 10; ++x) {
    const bool run = x < 6;
    px[static_cast<std::size_t>(x)] = {static_cast<std::uint8_t>(run ? 200 : 10 + x),
                                       static_cast<std::uint8_t>(run ? 100 : 20 + x),
                                       static_cast<std::uint8_t>(run ? 50 : 30 + x),
                                       static_cast<std::uint8_t>(run ? 130 : 125 + x)};
  }
  return px;
}

Bytes rleScanline(const std::vector<std::array<std::uint8_t, 4>>& px) {
  Bytes b = {2, 2, 0, 10};
  for (std::size_t ch = 0; ch < 4; ++ch) {
    b.push_back(128 + 6);
    b.push_back(px[0][ch]);
    b.push_back(4);
    for (std::size_t x = 6; x < 10; ++x) b.push_back(px[x][ch]);
  }
  return b;
}

// ------------------------------------------------------------------ OpenEXR

TEST_F(ImageIo, ExrRoundTripIsExact) {
  const RgbImage img = randomImage(37, 19, 1);
  writeExr(path("a.exr"), img);
  const RgbImage back = readExr(path("a.exr"));
  EXPECT_EQ(back.width, 37);
  EXPECT_EQ(back.height, 19);
  EXPECT_EQ(back.rgb, img.rgb);
  // The extension is matched case-insensitively.
  fs::copy_file(path("a.exr"), path("b.EXR"));
  EXPECT_EQ(readImage(path("b.EXR")).rgb, img.rgb);
}

// A minimal uncompressed single-part scanline OpenEXR file, written byte by
// byte from the OpenEXR "File Layout" document, for channel sets and headers
// that the writer does not produce. `lines[y][c]` holds channel c of row y.
Bytes handMadeExr(const std::vector<std::string>& channels, int xMax, int yMax,
                  const std::vector<std::vector<std::vector<float>>>& lines) {
  Bytes b = {0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0};
  const auto i32 = [&b](std::int32_t v) {
    for (int k = 0; k < 4; ++k) b.push_back(static_cast<std::uint8_t>(static_cast<std::uint32_t>(v) >> (8 * k)));
  };
  const auto f32 = [&i32](float v) {
    std::int32_t bits;
    std::memcpy(&bits, &v, 4);
    i32(bits);
  };
  const auto attribute = [&](const std::string& name, const std::string& type, std::int32_t size) {
    append(b, name);
    b.push_back(0);
    append(b, type);
    b.push_back(0);
    i32(size);
  };
  std::int32_t chlistSize = 1;
  for (const std::string& c : channels) chlistSize += static_cast<std::int32_t>(c.size()) + 1 + 16;
  attribute("channels", "chlist", chlistSize);
  for (const std::string& c : channels) {
    append(b, c);
    b.push_back(0);
    i32(2);                                  // FLOAT
    b.insert(b.end(), {0, 0, 0, 0});         // pLinear, reserved
    i32(1);                                  // xSampling
    i32(1);                                  // ySampling
  }
  b.push_back(0);
  attribute("compression", "compression", 1);
  b.push_back(0);  // NO_COMPRESSION
  attribute("dataWindow", "box2i", 16);
  for (std::int32_t v : {0, 0, xMax, yMax}) i32(v);
  attribute("displayWindow", "box2i", 16);
  for (std::int32_t v : {0, 0, xMax, yMax}) i32(v);
  attribute("lineOrder", "lineOrder", 1);
  b.push_back(0);  // INCREASING_Y
  attribute("pixelAspectRatio", "float", 4);
  f32(1.0f);
  attribute("screenWindowCenter", "v2f", 8);
  f32(0.0f);
  f32(0.0f);
  attribute("screenWindowWidth", "float", 4);
  f32(1.0f);
  b.push_back(0);  // end of header
  // Offset table, one entry per line (uncompressed chunks hold one line).
  const std::size_t tableAt = b.size();
  b.resize(b.size() + 8 * lines.size(), 0);
  for (std::size_t y = 0; y < lines.size(); ++y) {
    const std::uint64_t offset = b.size();
    for (int k = 0; k < 8; ++k) b[tableAt + 8 * y + static_cast<std::size_t>(k)] = static_cast<std::uint8_t>(offset >> (8 * k));
    i32(static_cast<std::int32_t>(y));
    std::int32_t size = 0;
    for (const auto& c : lines[y]) size += static_cast<std::int32_t>(c.size() * 4);
    i32(size);
    for (const auto& c : lines[y])
      for (float v : c) f32(v);
  }
  return b;
}

TEST_F(ImageIo, ExrWithOnlyYIsGrey) {
  writeBytes(path("y.exr"), handMadeExr({"Y"}, 2, 1, {{{1.0f, 2.0f, 3.0f}}, {{4.0f, 5.0f, 6.0f}}}));
  const RgbImage img = readExr(path("y.exr"));
  ASSERT_EQ(img.width, 3);
  ASSERT_EQ(img.height, 2);
  for (int row = 0; row < 2; ++row)
    for (int col = 0; col < 3; ++col)
      for (int ch = 0; ch < 3; ++ch) EXPECT_EQ(img.at(row, col, ch), static_cast<float>(1 + 3 * row + col));
}

TEST_F(ImageIo, ExrWithRgbaReadsRgb) {
  // Channels are stored alphabetically: A, B, G, R.
  writeBytes(path("rgba.exr"), handMadeExr({"A", "B", "G", "R"}, 0, 0, {{{9.0f}, {3.0f}, {2.0f}, {1.0f}}}));
  const RgbImage img = readExr(path("rgba.exr"));
  EXPECT_EQ(img.rgb, (std::vector<float>{1.0f, 2.0f, 3.0f}));
}

TEST_F(ImageIo, ExrFailures) {
  // Layered channel names are not an RGB image.
  writeBytes(path("layers.exr"), handMadeExr({"diffuse.B", "diffuse.G", "diffuse.R"}, 0, 0, {{{1.0f}, {2.0f}, {3.0f}}}));
  expectFailure([&] { readExr(path("layers.exr")); }, path("layers.exr"), "unsupported EXR channel layout");
  // A data window 40000 pixels wide is refused before anything is allocated.
  writeBytes(path("wide.exr"), handMadeExr({"Y"}, 39999, 0, {{{1.0f}}}));
  expectFailure([&] { readExr(path("wide.exr")); }, path("wide.exr"), "exceeds the maximum width of 32768");
  writeBytes(path("empty.exr"), {});
  expectFailure([&] { readExr(path("empty.exr")); }, path("empty.exr"), "empty file");
  Bytes notExr;
  append(notExr, "#?RADIANCE\n\n-Y 1 +X 1\n");
  writeBytes(path("magic.exr"), notExr);
  expectFailure([&] { readExr(path("magic.exr")); }, path("magic.exr"), "not an OpenEXR file");
  expectFailure([&] { readExr(path("missing.exr")); }, path("missing.exr"), "cannot open");
  // A real file cut in half.
  writeExr(path("full.exr"), randomImage(64, 64, 2));
  Bytes full = readBytes(path("full.exr"));
  full.resize(full.size() / 2);
  writeBytes(path("cut.exr"), full);
  expectFailure([&] { readExr(path("cut.exr")); }, path("cut.exr"), "");
}

// ------------------------------------------------------------------ Radiance

TEST_F(ImageIo, HdrFlatScanlines) {
  // Width 3 < 8: flat pixels; "-Y 2 +X 3" is top to bottom, left to right.
  Bytes b;
  append(b, "#?RADIANCE\n# a comment\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 3\n");
  const std::vector<std::array<std::uint8_t, 4>> px = {
      {128, 64, 32, 129}, {255, 0, 1, 140}, {0, 0, 0, 0}, {10, 20, 30, 100}, {1, 2, 3, 128}, {7, 7, 7, 136}};
  for (const auto& p : px) b.insert(b.end(), p.begin(), p.end());
  writeBytes(path("flat.hdr"), b);
  const RgbImage img = readRadianceHdr(path("flat.hdr"));
  ASSERT_EQ(img.width, 3);
  ASSERT_EQ(img.height, 2);
  for (int k = 0; k < 6; ++k) {
    for (int ch = 0; ch < 3; ++ch) {
      const auto& p = px[static_cast<std::size_t>(k)];
      EXPECT_EQ(img.at(k / 3, k % 3, ch), rgbeValue(p[static_cast<std::size_t>(ch)], p[3])) << k << " " << ch;
    }
  }
  EXPECT_FLOAT_EQ(img.at(0, 0, 0), 128.5f / 128.0f);
}

TEST_F(ImageIo, HdrRunLengthScanlinesMatchFlatOnes) {
  const auto px = rlePixels();
  Bytes rle, flat;
  append(rle, "#?RGBE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 10\n");
  append(flat, "#?RADIANCE\n\n-Y 2 +X 10\n");
  for (int line = 0; line < 2; ++line) {
    const Bytes s = rleScanline(px);
    rle.insert(rle.end(), s.begin(), s.end());
    for (const auto& p : px) flat.insert(flat.end(), p.begin(), p.end());
  }
  writeBytes(path("rle.hdr"), rle);
  writeBytes(path("flat.hdr"), flat);
  const RgbImage a = readRadianceHdr(path("rle.hdr"));
  const RgbImage b = readRadianceHdr(path("flat.hdr"));
  ASSERT_EQ(a.width, 10);
  ASSERT_EQ(a.height, 2);
  EXPECT_EQ(a.rgb, b.rgb);
  for (int x = 0; x < 10; ++x) EXPECT_EQ(a.at(1, x, 2), rgbeValue(px[static_cast<std::size_t>(x)][2], px[static_cast<std::size_t>(x)][3]));
}

TEST_F(ImageIo, HdrOldStyleRunsFlipsAndExposure) {
  // Old-style RLE: (1, 1, 1, 3) repeats the previous pixel three times.
  // "+Y" stores the bottom row first, "-X" right to left; EXPOSURE=2 twice
  // means the pixels were multiplied by 4.
  Bytes b;
  append(b, "#?RADIANCE\nEXPOSURE=2\nEXPOSURE=2.0\n\n+Y 2 -X 4\n");
  b.insert(b.end(), {128, 128, 128, 129, 1, 1, 1, 3});                            // bottom row, all equal
  b.insert(b.end(), {128, 0, 0, 129, 0, 128, 0, 129, 0, 0, 128, 129, 64, 64, 64, 129});  // top row, right to left
  writeBytes(path("old.hdr"), b);
  const RgbImage img = readImage(path("old.hdr"));
  ASSERT_EQ(img.width, 4);
  const float one = rgbeValue(128, 129) / 4.0f;
  for (int x = 0; x < 4; ++x) EXPECT_EQ(img.at(1, x, 1), one);
  EXPECT_EQ(img.at(0, 3, 0), one);  // first stored pixel is the rightmost
  EXPECT_EQ(img.at(0, 2, 1), one);
  EXPECT_EQ(img.at(0, 1, 2), one);
  EXPECT_EQ(img.at(0, 0, 0), rgbeValue(64, 129) / 4.0f);
}

TEST_F(ImageIo, HdrFailures) {
  writeBytes(path("empty.hdr"), {});
  expectFailure([&] { readRadianceHdr(path("empty.hdr")); }, path("empty.hdr"), "empty file");

  Bytes magic;
  append(magic, "P6\n2 2\n255\n");
  writeBytes(path("magic.hdr"), magic);
  expectFailure([&] { readRadianceHdr(path("magic.hdr")); }, path("magic.hdr"), "not a Radiance file");

  Bytes huge;
  append(huge, "#?RADIANCE\n\n-Y 100000 +X 100000\n");
  writeBytes(path("huge.hdr"), huge);
  expectFailure([&] { readRadianceHdr(path("huge.hdr")); }, path("huge.hdr"), "bad dimensions");

  Bytes zero;
  append(zero, "#?RADIANCE\n\n-Y 0 +X 8\n");
  writeBytes(path("zero.hdr"), zero);
  expectFailure([&] { readRadianceHdr(path("zero.hdr")); }, path("zero.hdr"), "bad dimensions");

  // Within limits, but far more rows than the bytes can hold: refused before allocating.
  Bytes tall;
  append(tall, "#?RADIANCE\n\n-Y 16000 +X 16000\n");
  tall.resize(tall.size() + 100, 0);
  writeBytes(path("tall.hdr"), tall);
  expectFailure([&] { readRadianceHdr(path("tall.hdr")); }, path("tall.hdr"), "truncated file");

  // Two RLE scanlines announced, the second cut short.
  Bytes cut;
  append(cut, "#?RADIANCE\n\n-Y 2 +X 10\n");
  const Bytes s = rleScanline(rlePixels());
  cut.insert(cut.end(), s.begin(), s.end());
  cut.insert(cut.end(), s.begin(), s.end() - 3);
  writeBytes(path("cut.hdr"), cut);
  expectFailure([&] { readRadianceHdr(path("cut.hdr")); }, path("cut.hdr"), "truncated scanline 1 of 2");

  Bytes noBlank;
  append(noBlank, "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n");
  writeBytes(path("noblank.hdr"), noBlank);
  expectFailure([&] { readRadianceHdr(path("noblank.hdr")); }, path("noblank.hdr"), "truncated header");

  Bytes xyz;
  append(xyz, "#?RADIANCE\nFORMAT=32-bit_rle_xyze\n\n-Y 1 +X 1\n");
  xyz.insert(xyz.end(), {1, 2, 3, 4});
  writeBytes(path("xyz.hdr"), xyz);
  expectFailure([&] { readRadianceHdr(path("xyz.hdr")); }, path("xyz.hdr"), "unsupported Radiance FORMAT");

  Bytes transposed;
  append(transposed, "#?RADIANCE\n\n+X 1 -Y 1\n");
  transposed.insert(transposed.end(), {1, 2, 3, 4});
  writeBytes(path("transposed.hdr"), transposed);
  expectFailure([&] { readRadianceHdr(path("transposed.hdr")); }, path("transposed.hdr"), "resolution line");

  // A run that would write past the end of the scanline.
  Bytes overrun;
  append(overrun, "#?RADIANCE\n\n-Y 1 +X 10\n");
  overrun.insert(overrun.end(), {2, 2, 0, 10, 128 + 11, 5});
  overrun.resize(overrun.size() + 64, 0);
  writeBytes(path("overrun.hdr"), overrun);
  expectFailure([&] { readRadianceHdr(path("overrun.hdr")); }, path("overrun.hdr"), "corrupt scanline 0");
}

// ------------------------------------------------------------------ PFM

TEST_F(ImageIo, PfmRoundTripIsExact) {
  const RgbImage img = randomImage(13, 7, 3);
  writePfm(path("a.pfm"), img);
  const RgbImage back = readImage(path("a.pfm"));
  EXPECT_EQ(back.width, 13);
  EXPECT_EQ(back.height, 7);
  EXPECT_EQ(back.rgb, img.rgb);
  // Rows are stored bottom to top: the first float in the file is the bottom-left red.
  const Bytes raw = readBytes(path("a.pfm"));
  const std::string header = "PF\n13 7\n-1.0\n";
  ASSERT_EQ(std::string(raw.begin(), raw.begin() + static_cast<std::ptrdiff_t>(header.size())), header);
  float first;
  std::memcpy(&first, &raw[header.size()], 4);
  EXPECT_EQ(first, img.at(6, 0, 0));
}

TEST_F(ImageIo, PfmGreyBigEndian) {
  // "Pf" is one channel; a positive scale means big-endian floats.
  Bytes b;
  append(b, "Pf\n2 2\n1.0\n");
  for (float v : {1.0f, 2.0f, 3.0f, 4.0f}) {  // bottom row first
    std::uint32_t bits;
    std::memcpy(&bits, &v, 4);
    for (int k = 3; k >= 0; --k) b.push_back(static_cast<std::uint8_t>(bits >> (8 * k)));
  }
  writeBytes(path("grey.pfm"), b);
  const RgbImage img = readPfm(path("grey.pfm"));
  EXPECT_EQ(img.rgb, (std::vector<float>{3, 3, 3, 4, 4, 4, 1, 1, 1, 2, 2, 2}));
}

TEST_F(ImageIo, PfmFailures) {
  writeBytes(path("empty.pfm"), {});
  expectFailure([&] { readPfm(path("empty.pfm")); }, path("empty.pfm"), "empty file");
  Bytes magic;
  append(magic, "P6\n1 1\n255\n\x01\x02\x03");
  writeBytes(path("magic.pfm"), magic);
  expectFailure([&] { readPfm(path("magic.pfm")); }, path("magic.pfm"), "not a PFM file");
  Bytes huge;
  append(huge, "PF\n40000 2\n-1.0\n");
  writeBytes(path("huge.pfm"), huge);
  expectFailure([&] { readPfm(path("huge.pfm")); }, path("huge.pfm"), "bad dimensions");
  Bytes negative;
  append(negative, "PF\n-4 2\n-1.0\n");
  writeBytes(path("negative.pfm"), negative);
  expectFailure([&] { readPfm(path("negative.pfm")); }, path("negative.pfm"), "bad dimensions");
  writePfm(path("full.pfm"), randomImage(8, 8, 4));
  Bytes cut = readBytes(path("full.pfm"));
  cut.resize(cut.size() - 5);
  writeBytes(path("cut.pfm"), cut);
  expectFailure([&] { readPfm(path("cut.pfm")); }, path("cut.pfm"), "truncated pixel data");
}

// ------------------------------------------------------------------ PNG, dispatch

TEST_F(ImageIo, PngIsEightBitRgbOfTheImageSize) {
  RgbImage img = makeImage(5, 3);
  img.at(0, 0, 0) = 1.0f;
  img.at(2, 4, 1) = std::nanf("");
  writePng(path("a.png"), img, 1.0);
  const Bytes raw = readBytes(path("a.png"));
  ASSERT_GT(raw.size(), 33u);
  EXPECT_EQ(std::memcmp(raw.data(), "\x89PNG\r\n\x1a\n", 8), 0);
  // IHDR: big-endian width and height, bit depth 8, colour type 2 (RGB).
  EXPECT_EQ(std::memcmp(&raw[12], "IHDR", 4), 0);
  EXPECT_EQ(raw[19], 5);
  EXPECT_EQ(raw[23], 3);
  EXPECT_EQ(raw[24], 8);
  EXPECT_EQ(raw[25], 2);
  expectFailure([&] { writePng(path("no/such/dir/a.png"), img); }, path("no/such/dir/a.png"), "cannot write PNG");
  RgbImage bad = img;
  bad.rgb.pop_back();
  EXPECT_THROW(writePng(path("b.png"), bad), std::invalid_argument);
  EXPECT_THROW(writeExr(path("b.exr"), bad), std::invalid_argument);
  EXPECT_THROW(writePfm(path("b.pfm"), bad), std::invalid_argument);
}

TEST_F(ImageIo, ReadImageDispatchesOnExtension) {
  const RgbImage img = randomImage(4, 2, 5);
  writePfm(path("x.PFM"), img);
  EXPECT_EQ(readImage(path("x.PFM")).rgb, img.rgb);
  expectFailure([&] { readImage(path("x.tga")); }, path("x.tga"), "unknown image extension");
  // A PFM named .hdr is read as Radiance, and says so.
  fs::copy_file(path("x.PFM"), path("x.hdr"));
  expectFailure([&] { readImage(path("x.hdr")); }, path("x.hdr"), "not a Radiance file");
}

TEST(MakeImage, RefusesAbsurdSizes) {
  EXPECT_THROW(makeImage(0, 4), std::invalid_argument);
  EXPECT_THROW(makeImage(4, -1), std::invalid_argument);
  EXPECT_THROW(makeImage(kMaxImageDimension + 1, 1), std::invalid_argument);
  EXPECT_THROW(makeImage(kMaxImageDimension, kMaxImageDimension), std::invalid_argument);
  EXPECT_EQ(makeImage(3, 2).rgb.size(), 18u);
}

}  // namespace
}  // namespace haarcast::io
