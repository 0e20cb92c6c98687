// Linear RGB float images and the file formats haarcast reads and writes them
// in: OpenEXR, Radiance HDR (RGBE), PFM, and 8-bit sRGB PNG for viewing.
//
// Every failure — a missing file, a wrong magic number, a truncated scanline,
// a header that asks for an absurd size — throws std::runtime_error whose
// message starts with the path and says what was wrong
// ("probe.hdr: truncated scanline 37 of 128"). Sizes are checked against the
// limits below before anything is allocated, so a corrupt header cannot make
// the reader ask for gigabytes.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace haarcast::io {

// Largest width or height accepted from a file (and by the writers).
inline constexpr int kMaxImageDimension = 32768;
// Largest pixel count: 2^28 pixels is 3 GiB of float RGB, a 32768×8192
// lat-long; beyond that a header is corrupt, not a probe.
inline constexpr std::size_t kMaxImagePixels = std::size_t{1} << 28;

// A linear RGB image: row-major, three floats per pixel, row 0 is the top.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // width·height·3 floats

  std::size_t index(int row, int col) const {
    return (static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
            static_cast<std::size_t>(col)) * 3;
  }
  float& at(int row, int col, int channel) { return rgb[index(row, col) + static_cast<std::size_t>(channel)]; }
  float at(int row, int col, int channel) const { return rgb[index(row, col) + static_cast<std::size_t>(channel)]; }
};

// An all-zero image of the given size; throws std::invalid_argument unless
// 0 < width, height <= kMaxImageDimension and the pixel count is within kMaxImagePixels.
RgbImage makeImage(int width, int height);

// OpenEXR (any compression, scanline or tiled, half/float/uint channels,
// read through the data window). R, G, B are read as float (A is ignored); a
// file with only Y is grey; Y/RY/BY luminance-chroma files go through
// OpenEXR's RGBA conversion. Any other channel set (layers, multi-view
// names) is "unsupported EXR channel layout".
RgbImage readExr(const std::string& path);

// Radiance RGBE (Greg Ward's .hdr/.pic): "#?RADIANCE" or "#?RGBE" magic,
// FORMAT=32-bit_rle_rgbe, the resolution line "-Y h +X w" (also "+Y" and "-X"
// flips), new-style run-length, old-style run-length and flat scanlines.
// Values are divided by the product of the header's EXPOSURE= lines, which
// the format defines as multipliers already applied to the pixels.
RgbImage readRadianceHdr(const std::string& path);

// Portable float map: "PF" (RGB) or "Pf" (grey), a negative scale means
// little-endian floats, rows stored bottom to top. |scale| is ignored (it
// carries no agreed meaning for HDR data).
RgbImage readPfm(const std::string& path);

// Dispatches on the extension, case-insensitively: .exr, .hdr/.pic/.rgbe, .pfm.
RgbImage readImage(const std::string& path);

// Float RGB OpenEXR, ZIP compression (lossless: a float image reads back equal).
void writeExr(const std::string& path, const RgbImage& image);

// Little-endian colour PFM ("PF", scale −1), bottom-to-top rows as the format
// requires: reads back bit-identical.
void writePfm(const std::string& path, const RgbImage& image);

// 8-bit sRGB PNG for viewing: each linear value is multiplied by
// 2^exposureStops, clamped to [0, 1] (NaN → 0), encoded with the sRGB transfer
// function (IEC 61966-2-1) and rounded.
void writePng(const std::string& path, const RgbImage& image, double exposureStops = 0.0);

// An already encoded 8-bit sRGB image (render::tonemapRgba8's layout: row 0
// at the top, 4 bytes per pixel) as an RGBA PNG.
void writePngRgba8(const std::string& path, const std::vector<std::uint8_t>& rgba8, int width, int height);

// One linear value to an 8-bit sRGB byte: clamped to [0, 1] (NaN → 0), the
// IEC 61966-2-1 transfer function, rounded. writePng and every tonemap use it.
std::uint8_t encodeSrgb(double linear);

}  // namespace haarcast::io
