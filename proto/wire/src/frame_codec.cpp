#include "haarcast/wire/frame_codec.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <stdexcept>

#include <png.h>
#include <turbojpeg.h>

#include "size_checks.h"

namespace haarcast::wire {
namespace {

using detail::checkDecodedSize;
using detail::sizeText;

void checkRgba8(std::span<const std::uint8_t> rgba8, std::uint32_t width, std::uint32_t height, const char* codec) {
  if (!detail::sizeIsSane(width, height)) {
    throw std::runtime_error(std::string(codec) + ": bad image size " + sizeText(width, height));
  }
  const std::size_t expected = std::size_t{width} * std::size_t{height} * 4;
  if (rgba8.size() != expected) {
    throw std::runtime_error(std::string(codec) + ": RGBA8 buffer holds " + std::to_string(rgba8.size()) +
                             " bytes, expected " + std::to_string(expected));
  }
}

// tjhandle owner: tjDestroy on every path, so a throwing codec leaks nothing.
struct TjHandle {
  tjhandle h;
  explicit TjHandle(tjhandle handle) : h(handle) {
    if (!h) throw std::runtime_error(std::string("jpeg: cannot create a libjpeg-turbo handle: ") + tjGetErrorStr());
  }
  ~TjHandle() { tjDestroy(h); }
  TjHandle(const TjHandle&) = delete;
  TjHandle& operator=(const TjHandle&) = delete;
};

// png_image owner: png_image_free on every path (it is a no-op once freed).
struct PngImage {
  png_image image;
  PngImage() {
    std::memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
  }
  ~PngImage() { png_image_free(&image); }
  PngImage(const PngImage&) = delete;
  PngImage& operator=(const PngImage&) = delete;
};

}  // namespace

std::string encodeJpeg(std::span<const std::uint8_t> rgba8, std::uint32_t width, std::uint32_t height,
                       int jpegQuality) {
  checkRgba8(rgba8, width, height, "jpeg");
  TjHandle tj(tjInitCompress());
  unsigned char* out = nullptr;
  unsigned long size = 0;
  const int quality = std::clamp(jpegQuality, 1, 100);
  if (tjCompress2(tj.h, rgba8.data(), static_cast<int>(width), 0, static_cast<int>(height), TJPF_RGBA, &out, &size,
                  TJSAMP_420, quality, 0) != 0) {
    if (out) tjFree(out);
    throw std::runtime_error(std::string("jpeg: tjCompress2 failed: ") + tjGetErrorStr2(tj.h));
  }
  std::string bytes(reinterpret_cast<const char*>(out), size);
  tjFree(out);
  return bytes;
}

std::string encodePng(std::span<const std::uint8_t> rgba8, std::uint32_t width, std::uint32_t height) {
  checkRgba8(rgba8, width, height, "png");
  PngImage png;
  png.image.width = width;
  png.image.height = height;
  png.image.format = PNG_FORMAT_RGBA;
  // The simplified API sizes the output first (a null buffer), then writes.
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&png.image, nullptr, &size, 0, rgba8.data(), 0, nullptr)) {
    throw std::runtime_error(std::string("png: cannot encode: ") + png.image.message);
  }
  std::string bytes(size, '\0');
  if (!png_image_write_to_memory(&png.image, bytes.data(), &size, 0, rgba8.data(), 0, nullptr)) {
    throw std::runtime_error(std::string("png: cannot encode: ") + png.image.message);
  }
  bytes.resize(size);
  return bytes;
}

std::string encodeRaw(std::span<const std::uint8_t> rgba8, std::uint32_t width, std::uint32_t height) {
  checkRgba8(rgba8, width, height, "raw");
  return std::string(reinterpret_cast<const char*>(rgba8.data()), rgba8.size());
}

Rgba8Image decodeJpeg(std::string_view bytes, std::optional<ImageSize> expected) {
  if (bytes.empty() || bytes.size() > std::numeric_limits<unsigned long>::max()) {
    throw std::runtime_error("jpeg: no data to decode");
  }
  TjHandle tj(tjInitDecompress());
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(tj.h, data, bytes.size(), &width, &height, &subsampling, &colorspace) != 0) {
    throw std::runtime_error(std::string("jpeg: bad header: ") + tjGetErrorStr2(tj.h));
  }
  const ImageSize size = checkDecodedSize("jpeg", width, height, expected);
  Rgba8Image image{size.width, size.height, std::vector<std::uint8_t>(std::size_t{size.width} * size.height * 4)};
  if (tjDecompress2(tj.h, data, bytes.size(), image.pixels.data(), width, 0, height, TJPF_RGBA, 0) != 0) {
    throw std::runtime_error(std::string("jpeg: cannot decode: ") + tjGetErrorStr2(tj.h));
  }
  return image;
}

Rgba8Image decodePng(std::string_view bytes, std::optional<ImageSize> expected) {
  PngImage png;
  if (!png_image_begin_read_from_memory(&png.image, bytes.data(), bytes.size())) {
    throw std::runtime_error(std::string("png: bad header: ") + png.image.message);
  }
  const ImageSize size = checkDecodedSize("png", png.image.width, png.image.height, expected);
  png.image.format = PNG_FORMAT_RGBA;
  Rgba8Image image{size.width, size.height, std::vector<std::uint8_t>(PNG_IMAGE_SIZE(png.image))};
  if (!png_image_finish_read(&png.image, nullptr, image.pixels.data(), 0, nullptr)) {
    throw std::runtime_error(std::string("png: cannot decode: ") + png.image.message);
  }
  return image;
}

Rgba8Image decodeRaw(std::string_view bytes, ImageSize size) {
  if (!detail::sizeIsSane(size.width, size.height)) {
    throw std::runtime_error("raw: bad image size " + sizeText(size.width, size.height));
  }
  const std::size_t want = std::size_t{size.width} * size.height * 4;
  if (bytes.size() != want) {
    throw std::runtime_error("raw: the frame has " + std::to_string(bytes.size()) + " bytes, " +
                             sizeText(size.width, size.height) + " RGBA8 needs " + std::to_string(want));
  }
  return {size.width, size.height, std::vector<std::uint8_t>(bytes.begin(), bytes.end())};
}

}  // namespace haarcast::wire
