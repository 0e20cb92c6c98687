#include "haarcast/net/encode.h"

#include <algorithm>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>

#include <png.h>
#include <turbojpeg.h>

#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfRgbaFile.h>
#include <ImfArray.h>

namespace haarcast::net {
namespace {

void checkRgba(const std::vector<std::uint8_t>& rgba8, int width, int height, const char* codec) {
  if (width <= 0 || height <= 0 || width > io::kMaxImageDimension || height > io::kMaxImageDimension) {
    throw std::runtime_error(std::string(codec) + ": bad image size " + std::to_string(width) + "x" +
                             std::to_string(height));
  }
  const std::size_t expected = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4;
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

// OpenEXR reads and writes through these streams, so a frame never touches
// the disk (the library's own StdOSStream would copy through a stringstream).
class MemoryOStream final : public Imf::OStream {
 public:
  MemoryOStream() : Imf::OStream("<memory>") {}
  void write(const char c[], int n) override {
    const std::size_t end = pos_ + static_cast<std::size_t>(n);
    if (end > data_.size()) data_.resize(end);
    std::memcpy(data_.data() + pos_, c, static_cast<std::size_t>(n));
    pos_ = end;
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = static_cast<std::size_t>(pos); }
  std::string take() { return std::move(data_); }

 private:
  std::string data_;
  std::size_t pos_ = 0;
};

class MemoryIStream final : public Imf::IStream {
 public:
  explicit MemoryIStream(std::string_view data) : Imf::IStream("<memory>"), data_(data) {}
  bool read(char c[], int n) override {
    if (n < 0 || pos_ + static_cast<std::size_t>(n) > data_.size()) {
      throw std::runtime_error("exr: unexpected end of data");
    }
    std::memcpy(c, data_.data() + pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::size_t>(n);
    return pos_ < data_.size();
  }
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override { pos_ = static_cast<std::size_t>(std::min<uint64_t>(pos, data_.size())); }

 private:
  std::string_view data_;
  std::size_t pos_ = 0;
};

}  // namespace

std::string_view encodingName(FrameEncoding encoding) {
  switch (encoding) {
    case FrameEncoding::Jpeg: return "jpeg";
    case FrameEncoding::Png: return "png";
    case FrameEncoding::RawRgba8: return "raw";
    case FrameEncoding::Exr: return "exr";
    case FrameEncoding::H264: return "h264";
  }
  return "unknown";
}

std::string encodeJpeg(const std::vector<std::uint8_t>& rgba8, int width, int height, int jpegQuality) {
  checkRgba(rgba8, width, height, "jpeg");
  TjHandle tj(tjInitCompress());
  unsigned char* out = nullptr;
  unsigned long size = 0;
  const int quality = std::clamp(jpegQuality, 1, 100);
  if (tjCompress2(tj.h, rgba8.data(), width, 0, height, TJPF_RGBA, &out, &size, TJSAMP_420, quality, 0) != 0) {
    if (out) tjFree(out);
    throw std::runtime_error(std::string("jpeg: tjCompress2 failed: ") + tjGetErrorStr2(tj.h));
  }
  std::string bytes(reinterpret_cast<const char*>(out), size);
  tjFree(out);
  return bytes;
}

std::string encodePng(const std::vector<std::uint8_t>& rgba8, int width, int height) {
  checkRgba(rgba8, width, height, "png");
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(width);
  image.height = static_cast<png_uint_32>(height);
  image.format = PNG_FORMAT_RGBA;
  // The simplified API sizes the output first (a null buffer), then writes.
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&image, nullptr, &size, 0, rgba8.data(), 0, nullptr)) {
    const std::string message = image.message;
    png_image_free(&image);
    throw std::runtime_error("png: cannot encode: " + message);
  }
  std::string bytes(size, '\0');
  if (!png_image_write_to_memory(&image, bytes.data(), &size, 0, rgba8.data(), 0, nullptr)) {
    const std::string message = image.message;
    png_image_free(&image);
    throw std::runtime_error("png: cannot encode: " + message);
  }
  bytes.resize(size);
  return bytes;
}

std::string encodeRaw(const std::vector<std::uint8_t>& rgba8, int width, int height) {
  checkRgba(rgba8, width, height, "raw");
  return std::string(reinterpret_cast<const char*>(rgba8.data()), rgba8.size());
}

std::string encodeExr(const io::RgbImage& linear) {
  const int w = linear.width, h = linear.height;
  if (w <= 0 || h <= 0 || linear.rgb.size() != static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 3) {
    throw std::runtime_error("exr: bad linear image (" + std::to_string(w) + "x" + std::to_string(h) + ", " +
                             std::to_string(linear.rgb.size()) + " floats)");
  }
  std::vector<Imf::Rgba> pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    pixels[i] = Imf::Rgba(linear.rgb[3 * i], linear.rgb[3 * i + 1], linear.rgb[3 * i + 2], 1.0f);
  }
  MemoryOStream stream;
  try {
    Imf::Header header(w, h);
    header.compression() = Imf::ZIP_COMPRESSION;
    // One thread: the server encodes many small frames concurrently already.
    Imf::RgbaOutputFile file(stream, header, Imf::WRITE_RGB, 0);
    file.setFrameBuffer(pixels.data(), 1, static_cast<std::size_t>(w));
    file.writePixels(h);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("exr: cannot encode: ") + e.what());
  }
  return stream.take();
}

std::string encodeFrame(FrameEncoding encoding, const std::vector<std::uint8_t>& rgba8, int width, int height,
                        const io::RgbImage& linear, int jpegQuality) {
  switch (encoding) {
    case FrameEncoding::Jpeg: return encodeJpeg(rgba8, width, height, jpegQuality);
    case FrameEncoding::Png: return encodePng(rgba8, width, height);
    case FrameEncoding::RawRgba8: return encodeRaw(rgba8, width, height);
    case FrameEncoding::Exr: return encodeExr(linear);
    case FrameEncoding::H264:
      throw std::logic_error("encodeFrame: H.264 frames depend on the ones before; the session's H264Encoder encodes them");
  }
  throw std::runtime_error("encodeFrame: unknown encoding");
}

Rgba8Image decodeJpeg(std::string_view bytes) {
  if (bytes.empty() || bytes.size() > std::numeric_limits<unsigned long>::max()) {
    throw std::runtime_error("jpeg: no data to decode");
  }
  TjHandle tj(tjInitDecompress());
  auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(tj.h, data, bytes.size(), &width, &height, &subsampling, &colorspace) != 0) {
    throw std::runtime_error(std::string("jpeg: bad header: ") + tjGetErrorStr2(tj.h));
  }
  if (width <= 0 || height <= 0 || width > io::kMaxImageDimension || height > io::kMaxImageDimension) {
    throw std::runtime_error("jpeg: absurd size " + std::to_string(width) + "x" + std::to_string(height));
  }
  Rgba8Image image{width, height, std::vector<std::uint8_t>(static_cast<std::size_t>(width) * height * 4)};
  if (tjDecompress2(tj.h, data, bytes.size(), image.rgba.data(), width, 0, height, TJPF_RGBA, 0) != 0) {
    throw std::runtime_error(std::string("jpeg: cannot decode: ") + tjGetErrorStr2(tj.h));
  }
  return image;
}

Rgba8Image decodePng(std::string_view bytes) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size())) {
    const std::string message = image.message;
    png_image_free(&image);
    throw std::runtime_error("png: bad header: " + message);
  }
  if (image.width == 0 || image.height == 0 || image.width > static_cast<png_uint_32>(io::kMaxImageDimension) ||
      image.height > static_cast<png_uint_32>(io::kMaxImageDimension)) {
    png_image_free(&image);
    throw std::runtime_error("png: absurd size");
  }
  image.format = PNG_FORMAT_RGBA;
  Rgba8Image out{static_cast<int>(image.width), static_cast<int>(image.height),
                 std::vector<std::uint8_t>(PNG_IMAGE_SIZE(image))};
  if (!png_image_finish_read(&image, nullptr, out.rgba.data(), 0, nullptr)) {
    const std::string message = image.message;
    png_image_free(&image);
    throw std::runtime_error("png: cannot decode: " + message);
  }
  return out;
}

io::RgbImage decodeExr(std::string_view bytes) {
  try {
    MemoryIStream stream(bytes);
    Imf::RgbaInputFile file(stream, 1);
    const Imath::Box2i dw = file.dataWindow();
    const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
    io::RgbImage image = io::makeImage(w, h);
    std::vector<Imf::Rgba> pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    // The frame buffer is addressed by absolute data-window coordinates.
    const std::ptrdiff_t origin = -static_cast<std::ptrdiff_t>(dw.min.x) - static_cast<std::ptrdiff_t>(dw.min.y) * w;
    file.setFrameBuffer(pixels.data() + origin, 1, static_cast<std::size_t>(w));
    file.readPixels(dw.min.y, dw.max.y);
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      image.rgb[3 * i] = pixels[i].r;
      image.rgb[3 * i + 1] = pixels[i].g;
      image.rgb[3 * i + 2] = pixels[i].b;
    }
    return image;
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("exr: cannot decode: ") + e.what());
  }
}

}  // namespace haarcast::net
