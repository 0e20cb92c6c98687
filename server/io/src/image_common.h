// What the image readers share (image.cpp: OpenEXR, PFM, PNG; radiance.cpp:
// Radiance HDR): the error convention, the size checks made before any
// pixel is allocated, and a cursor over a file's bytes.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "haarcast/io/image.h"
#include "haarcast/io/input_file.h"

namespace haarcast::io::detail {

[[noreturn]] inline void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

inline std::string sizeText(long long width, long long height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// The one size check of every reader, done before any pixel is allocated.
inline void checkFileDimensions(const std::string& path, long long width, long long height) {
  if (width <= 0 || height <= 0 || width > kMaxImageDimension || height > kMaxImageDimension) {
    fail(path, "bad dimensions " + sizeText(width, height) + " (each must be in [1, " +
                   std::to_string(kMaxImageDimension) + "])");
  }
  if (static_cast<unsigned long long>(width) * static_cast<unsigned long long>(height) > kMaxImagePixels) {
    fail(path, "image of " + sizeText(width, height) + " pixels exceeds the limit of " +
                   std::to_string(kMaxImagePixels) + " pixels");
  }
}

// Writers refuse malformed images: a caller's bug, hence invalid_argument.
inline void checkImage(const std::string& path, const RgbImage& image) {
  if (image.width <= 0 || image.height <= 0 || image.width > kMaxImageDimension ||
      image.height > kMaxImageDimension ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3) {
    throw std::invalid_argument(path + ": cannot write a " + sizeText(image.width, image.height) +
                                " image holding " + std::to_string(image.rgb.size()) + " floats");
  }
}

// Makes room for `more` floats at the end of `pixels`, whose final size is
// `total`: capacity doubles (never past `total`), so a reader that grows the
// image with the data it has decoded allocates at most twice what the file
// has delivered, and exactly `total` once it is all there. A header alone
// never sizes the pixels: old-style Radiance runs let 12 bytes stand for a
// 32768-pixel scanline and a ZIP'd EXR chunk can hold thousands of pixels a
// byte, so only the decoded data bounds the image by the file.
inline void growPixels(std::vector<float>& pixels, std::size_t more, std::size_t total) {
  const std::size_t needed = pixels.size() + more;
  if (needed > pixels.capacity()) pixels.reserve(std::min(total, std::max(needed, 2 * pixels.capacity())));
  pixels.resize(needed);
}

inline std::vector<std::uint8_t> readFileBytes(const std::string& path) {
  if (auto why = whyNotRegularFile(path)) fail(path, "cannot open for reading: " + *why);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) fail(path, "cannot open for reading");
  const std::streamoff size = in.tellg();
  if (size < 0) fail(path, "cannot determine the file size");
  if (size == 0) fail(path, "empty file");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), size)) fail(path, "read error");
  return bytes;
}

// A cursor over the file's bytes that never reads past the end.
struct ByteCursor {
  const std::uint8_t* pos;
  const std::uint8_t* end;
  std::size_t left() const { return static_cast<std::size_t>(end - pos); }
};

}  // namespace haarcast::io::detail
