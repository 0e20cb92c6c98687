#include "haarcast/client/frame_image.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>

#include <ImfArray.h>
#include <ImfIO.h>
#include <ImfRgbaFile.h>
#include <png.h>
#include <turbojpeg.h>

#include "haarcast/client/h264_decoder.h"

namespace haarcast::client {

namespace {

std::string sizeText(std::uint32_t w, std::uint32_t h) { return std::to_string(w) + "x" + std::to_string(h); }

void checkSize(const char* what, std::uint32_t gotW, std::uint32_t gotH, std::uint32_t wantW, std::uint32_t wantH) {
  if (gotW != wantW || gotH != wantH) {
    throw std::runtime_error(std::string(what) + " frame decodes to " + sizeText(gotW, gotH) +
                             " but the Frame message says " + sizeText(wantW, wantH));
  }
}

Rgba8Image decodeJpeg(std::span<const std::uint8_t> data, std::uint32_t width, std::uint32_t height) {
  std::unique_ptr<void, int (*)(tjhandle)> tj(tjInitDecompress(), tjDestroy);
  if (!tj) throw std::runtime_error("JPEG: tjInitDecompress failed");
  int w = 0, h = 0, subsamp = 0, colorspace = 0;
  // turbojpeg's API takes non-const buffers but does not write to them.
  auto* bytes = const_cast<unsigned char*>(data.data());
  const auto size = static_cast<unsigned long>(data.size());
  if (tjDecompressHeader3(tj.get(), bytes, size, &w, &h, &subsamp, &colorspace) != 0) {
    throw std::runtime_error(std::string("JPEG: bad header: ") + tjGetErrorStr2(tj.get()));
  }
  checkSize("JPEG", static_cast<std::uint32_t>(w), static_cast<std::uint32_t>(h), width, height);
  Rgba8Image out{width, height, std::vector<std::uint8_t>(std::size_t{width} * height * 4)};
  if (tjDecompress2(tj.get(), bytes, size, out.pixels.data(), w, 0, h, TJPF_RGBA, 0) != 0) {
    throw std::runtime_error(std::string("JPEG: decode failed: ") + tjGetErrorStr2(tj.get()));
  }
  return out;
}

Rgba8Image decodePng(std::span<const std::uint8_t> data, std::uint32_t width, std::uint32_t height) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&image, data.data(), data.size())) {
    throw std::runtime_error(std::string("PNG: bad header: ") + image.message);
  }
  checkSize("PNG", image.width, image.height, width, height);
  image.format = PNG_FORMAT_RGBA;
  Rgba8Image out{width, height, std::vector<std::uint8_t>(PNG_IMAGE_SIZE(image))};
  if (!png_image_finish_read(&image, nullptr, out.pixels.data(), 0, nullptr)) {
    const std::string message = image.message;
    png_image_free(&image);
    throw std::runtime_error("PNG: decode failed: " + message);
  }
  return out;
}

// OpenEXR reads from a stream; this one reads the frame's bytes in place.
class MemoryIStream final : public Imf::IStream {
 public:
  explicit MemoryIStream(std::span<const std::uint8_t> data) : Imf::IStream("frame.exr"), data_(data) {}
  bool read(char c[], int n) override {
    if (n < 0 || pos_ + static_cast<std::uint64_t>(n) > data_.size()) {
      throw std::runtime_error("EXR: truncated payload (" + std::to_string(data_.size()) + " bytes)");
    }
    std::memcpy(c, data_.data() + pos_, static_cast<std::size_t>(n));
    pos_ += static_cast<std::uint64_t>(n);
    return pos_ < data_.size();
  }
  std::uint64_t tellg() override { return pos_; }
  void seekg(std::uint64_t pos) override { pos_ = pos; }

 private:
  std::span<const std::uint8_t> data_;
  std::uint64_t pos_ = 0;
};

std::uint8_t toSrgb8(float linear) {
  const double v = std::clamp(static_cast<double>(linear), 0.0, 1.0);
  const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<std::uint8_t>(std::lround(s * 255.0));
}

Rgba8Image decodeExr(std::span<const std::uint8_t> data, std::uint32_t width, std::uint32_t height) {
  try {
    MemoryIStream stream(data);
    Imf::RgbaInputFile file(stream);
    const auto dw = file.dataWindow();
    const auto w = static_cast<std::uint32_t>(dw.max.x - dw.min.x + 1);
    const auto h = static_cast<std::uint32_t>(dw.max.y - dw.min.y + 1);
    checkSize("EXR", w, h, width, height);
    Imf::Array2D<Imf::Rgba> pixels(h, w);
    file.setFrameBuffer(&pixels[0][0] - dw.min.x - dw.min.y * static_cast<int>(w), 1, w);
    file.readPixels(dw.min.y, dw.max.y);
    Rgba8Image out{w, h, std::vector<std::uint8_t>(std::size_t{w} * h * 4)};
    for (std::uint32_t y = 0; y < h; ++y) {
      for (std::uint32_t x = 0; x < w; ++x) {
        const Imf::Rgba& p = pixels[y][x];
        std::uint8_t* o = &out.pixels[(std::size_t{y} * w + x) * 4];
        o[0] = toSrgb8(p.r);
        o[1] = toSrgb8(p.g);
        o[2] = toSrgb8(p.b);
        o[3] = 255;
      }
    }
    return out;
  } catch (const std::runtime_error&) {
    throw;
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("EXR: decode failed: ") + e.what());
  }
}

}  // namespace

Rgba8Image decodeFrame(v1::Encoding encoding, std::span<const std::uint8_t> data, std::uint32_t width,
                       std::uint32_t height) {
  if (width == 0 || height == 0) throw std::runtime_error("frame has no size (" + sizeText(width, height) + ")");
  switch (encoding) {
    case v1::ENCODING_JPEG: return decodeJpeg(data, width, height);
    case v1::ENCODING_PNG: return decodePng(data, width, height);
    case v1::ENCODING_EXR: return decodeExr(data, width, height);
    case v1::ENCODING_RAW_RGBA8: {
      const std::size_t want = std::size_t{width} * height * 4;
      if (data.size() != want) {
        throw std::runtime_error("RAW frame has " + std::to_string(data.size()) + " bytes, " + sizeText(width, height) +
                                 " RGBA8 needs " + std::to_string(want));
      }
      return {width, height, std::vector<std::uint8_t>(data.begin(), data.end())};
    }
    case v1::ENCODING_H264:
      throw std::runtime_error("H.264 frames depend on the ones before them: decode them in order with the "
                               "session's FrameDecoder");
    default:
      throw std::runtime_error("frame has unknown encoding " + std::to_string(static_cast<int>(encoding)));
  }
}

FrameDecoder::FrameDecoder() = default;
FrameDecoder::~FrameDecoder() = default;

Rgba8Image FrameDecoder::decode(v1::Encoding encoding, std::span<const std::uint8_t> data, std::uint32_t width,
                                std::uint32_t height) {
  if (encoding != v1::ENCODING_H264) return decodeFrame(encoding, data, width, height);
  if (!h264_) h264_ = std::make_unique<H264Decoder>();
  return h264_->decode(data, width, height);
}

PixelStats pixelStats(const Rgba8Image& image) {
  const std::size_t n = std::size_t{image.width} * image.height;
  if (n == 0) return {};
  // Welford's update: one pass, no catastrophic cancellation.
  double mean = 0.0, m2 = 0.0;
  std::size_t clipped = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* p = &image.pixels[i * 4];
    clipped += (p[0] == 255 || p[1] == 255 || p[2] == 255) ? 1 : 0;
    const double luma = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    const double delta = luma - mean;
    mean += delta / static_cast<double>(i + 1);
    m2 += delta * (luma - mean);
  }
  return {mean, std::sqrt(m2 / static_cast<double>(n)), static_cast<double>(clipped) / static_cast<double>(n)};
}

std::vector<std::uint8_t> encodePam(const Rgba8Image& image) {
  const std::string header = "P7\nWIDTH " + std::to_string(image.width) + "\nHEIGHT " + std::to_string(image.height) +
                             "\nDEPTH 4\nMAXVAL 255\nTUPLTYPE RGB_ALPHA\nENDHDR\n";
  std::vector<std::uint8_t> out(header.begin(), header.end());
  out.insert(out.end(), image.pixels.begin(), image.pixels.end());
  return out;
}

std::vector<std::uint8_t> encodePng(const Rgba8Image& image) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  png.width = image.width;
  png.height = image.height;
  png.format = PNG_FORMAT_RGBA;
  // The simplified API sizes the buffer on a first call without one.
  png_alloc_size_t size = 0;
  if (!png_image_write_to_memory(&png, nullptr, &size, 0, image.pixels.data(), 0, nullptr)) {
    throw std::runtime_error(std::string("PNG: encode failed: ") + png.message);
  }
  std::vector<std::uint8_t> out(size);
  if (!png_image_write_to_memory(&png, out.data(), &size, 0, image.pixels.data(), 0, nullptr)) {
    throw std::runtime_error(std::string("PNG: encode failed: ") + png.message);
  }
  out.resize(size);
  return out;
}

}  // namespace haarcast::client
