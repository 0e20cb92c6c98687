// Hostile headers: small files whose counts promise far more data than they
// hold. Each loader must refuse them naming the file, the count and the bytes
// there are, and must do so before it allocates for the count (the largest
// single heap request during the load stays small; AllocationPeak).
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "../allocation_tracking.h"
#include "haarcast/io/image.h"
#include "haarcast/io/mesh_io.h"

#include "../test_files.h"

namespace haarcast::io {
namespace {

using haarcast::testing::AllocationPeak;
using haarcast::testing::TempDir;
using haarcast::testing::writeFile;

// A refused hostile file may cost this much in one request (a scanline, a
// line buffer of OpenEXR's); what the header asks for is hundreds of MB.
constexpr std::size_t kSmallRequest = std::size_t{64} << 20;

// Runs `load`, expects a std::runtime_error holding every one of `parts`, and
// returns the largest heap request made meanwhile.
template <typename F>
std::size_t expectRefused(const F& load, const std::vector<std::string>& parts) {
  AllocationPeak peak;
  try {
    load();
    ADD_FAILURE() << "no exception; expected one mentioning \"" << parts.front() << "\"";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    for (const std::string& part : parts) {
      EXPECT_NE(what.find(part), std::string::npos) << "message \"" << what << "\" lacks \"" << part << "\"";
    }
  }
  return peak.largest();
}

std::string tempPrefix() { return "haarcast-loader-bounds-"; }

// The 221-byte shape of the bomb: a valid ASCII header declaring 50
// million vertices (the loader's own ceiling) over a one-triangle body. Before
// the check it reserved 1.2 GB of positions and normals, then failed reading.
TEST(LoaderBounds, AsciiPlyCountBeyondTheBodyIsRefusedBeforeAllocating) {
  TempDir dir(tempPrefix());
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 50000000\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n";
  const std::string path = writeFile(dir / "bomb.ply", ply);
  const std::size_t largest = expectRefused(
      [&] { loadPly(path); }, {path, "element vertex declares 50000000 entries", "599999999 bytes of ASCII data",
                               std::to_string(ply.size() - ply.find("0 0 0")) + " bytes after its header"});
  EXPECT_LT(largest, kSmallRequest);
}

TEST(LoaderBounds, BinaryPlyFaceCountBeyondTheBodyIsRefusedBeforeAllocating) {
  // Three float vertices fit; 40 million faces of at least one count byte do not.
  std::string ply =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 40000000\nproperty list uchar int vertex_indices\nend_header\n";
  ply += std::string(3 * 12 + 13, '\0');
  const std::size_t largest = expectRefused(
      [&] { parsePly(ply, "faces.ply"); },
      {"faces.ply", "element face declares 40000000 entries", "40000036 bytes of binary data", "49 bytes"});
  EXPECT_LT(largest, kSmallRequest);
}

TEST(LoaderBounds, AsciiPlyThatFitsItsCountsStillLoads) {
  // The bound is a lower bound: single-digit values, one space apart, exactly meet it.
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2";
  EXPECT_EQ(parsePly(ply, "tight").triangles.size(), 1u);
}

// Radiance: a 300-pixel-wide header needs at least 12 bytes a scanline.
TEST(LoaderBounds, HdrScanlineCountBeyondTheDataIsRefusedBeforeAllocating) {
  TempDir dir(tempPrefix());
  const std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 30000 +X 300\n" + std::string(100, '\x01');
  const std::string path = writeFile(dir / "tall.hdr", hdr);
  const std::size_t largest = expectRefused(
      [&] { readRadianceHdr(path); }, {path, "30000 scanlines of 300 pixels need at least 360000 bytes",
                                       "100 bytes of pixel data remain"});
  EXPECT_LT(largest, kSmallRequest);
}

// Old-style runs let 12 bytes stand for a 32768-pixel scanline, so a header of
// 32768 × 4096 passes the size bound in 48 KB. The first scanline is real; the
// second starts with a run escape, which is corrupt. The image grows with the
// decoded scanlines, so the refusal costs a scanline or two, not the 1.5 GB
// the header asks for.
TEST(LoaderBounds, HdrCorruptAfterItsFirstScanlineAllocatesOnlyWhatDecoded) {
  TempDir dir(tempPrefix());
  constexpr int kWidth = 32768, kHeight = 4096;
  std::string body = {'\x80', '\x80', '\x80', '\x81',   // one pixel,
                      '\x01', '\x01', '\x01', '\xff',   // 255 copies,
                      '\x01', '\x01', '\x01', '\x7f'};  // 127 << 8 more: 32768 in all
  body += std::string(12 * (kHeight - 1), '\x01');
  const std::string path = writeFile(
      dir / "runs.hdr", "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(kHeight) + " +X " +
                            std::to_string(kWidth) + "\n" + body);
  const std::size_t largest =
      expectRefused([&] { readRadianceHdr(path); }, {path, "corrupt scanline 1", "escape before the first pixel"});
  EXPECT_LE(largest, std::size_t{2} * kWidth * 3 * sizeof(float));
}

TEST(LoaderBounds, PfmPixelCountBeyondTheDataIsRefusedBeforeAllocating) {
  TempDir dir(tempPrefix());
  const std::string path = writeFile(dir / "big.pfm", "PF\n8000 8000\n-1.0\n" + std::string(64, '\0'));
  const std::size_t largest = expectRefused(
      [&] { readPfm(path); }, {path, "8000x8000 pixels of 3 floats need 768000000 bytes", "64 bytes remain"});
  EXPECT_LT(largest, kSmallRequest);
}

// Patches a written EXR's data window (the box2i after "dataWindow\0box2i\0"
// and its 4-byte size) to (0, 0)–(maxX, maxY).
std::string withDataWindow(std::string exr, int maxX, int maxY) {
  const std::string name("dataWindow\0box2i\0", 17);
  const std::size_t at = exr.find(name);
  EXPECT_NE(at, std::string::npos);
  const std::int32_t box[4] = {0, 0, maxX, maxY};
  std::memcpy(exr.data() + at + name.size() + 4, box, sizeof(box));
  return exr;
}

TEST(LoaderBounds, ExrDataWindowBeyondTheFileIsRefusedBeforeAllocating) {
  TempDir dir(tempPrefix());
  const std::string small = (dir / "small.exr").string();
  writeExr(small, makeImage(4, 4));
  const std::string bytes = haarcast::testing::readFile(small);
  // Room for the 512 offset-table entries OpenEXR reads on opening, not for
  // the chunks they point at.
  const std::string padded = withDataWindow(bytes, 32767, 8191) + std::string(5000, '\0');
  const std::string path = writeFile(dir / "window.exr", padded);
  const std::size_t largest = expectRefused(
      [&] { readExr(path); }, {path, "32768x8192 data window needs 512 chunks of at least 16 bytes",
                               std::to_string(padded.size()) + " bytes"});
  EXPECT_LT(largest, kSmallRequest);
  // Without the padding OpenEXR itself stops at the end of the offset table.
  const std::string bare = writeFile(dir / "bare.exr", withDataWindow(bytes, 32767, 8191));
  EXPECT_LT(expectRefused([&] { readExr(bare); }, {bare, "cannot read OpenEXR header", "Early end of file"}),
            kSmallRequest);
}

TEST(LoaderBounds, ExrDataWindowBeyondTheDimensionLimitIsRefusedByTheHeader) {
  TempDir dir(tempPrefix());
  const std::string small = (dir / "small.exr").string();
  writeExr(small, makeImage(4, 4));
  const std::string path =
      writeFile(dir / "huge.exr", withDataWindow(haarcast::testing::readFile(small), 1 << 30, 1 << 30));
  const std::size_t largest = expectRefused([&] { readExr(path); }, {path, "cannot read OpenEXR header"});
  EXPECT_LT(largest, kSmallRequest);
}

// A real file cut short: the pixels grow band by band, so the refusal costs
// less than the whole image.
TEST(LoaderBounds, ExrCutShortAllocatesLessThanTheWholeImage) {
  TempDir dir(tempPrefix());
  RgbImage image = makeImage(2048, 2048);
  for (std::size_t k = 0; k < image.rgb.size(); ++k) image.rgb[k] = static_cast<float>(k % 977) * 0.25f;
  const std::string whole = (dir / "whole.exr").string();
  writeExr(whole, image);
  const std::string bytes = haarcast::testing::readFile(whole);
  const std::string path = writeFile(dir / "cut.exr", bytes.substr(0, bytes.size() / 5));
  const std::size_t largest = expectRefused([&] { readExr(path); }, {path, "cannot read OpenEXR pixels"});
  EXPECT_LE(largest, image.rgb.size() * sizeof(float) / 2);
}

}  // namespace
}  // namespace haarcast::io
