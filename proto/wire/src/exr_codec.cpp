#include "haarcast/wire/exr_codec.h"

#include <algorithm>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <vector>

#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfRgbaFile.h>

#include "size_checks.h"

namespace haarcast::wire {
namespace {

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
      throw std::runtime_error("unexpected end of data (" + std::to_string(data_.size()) + " bytes)");
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

std::string encodeExr(std::span<const float> rgb, std::uint32_t width, std::uint32_t height) {
  if (!detail::sizeIsSane(width, height) || rgb.size() != std::size_t{width} * std::size_t{height} * 3) {
    throw std::runtime_error("exr: bad linear image (" + detail::sizeText(width, height) + ", " +
                             std::to_string(rgb.size()) + " floats)");
  }
  std::vector<Imf::Rgba> pixels(std::size_t{width} * std::size_t{height});
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = Imf::Rgba(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2], 1.0f);
  MemoryOStream stream;
  try {
    Imf::Header header(static_cast<int>(width), static_cast<int>(height));
    header.compression() = Imf::ZIP_COMPRESSION;
    // One thread: the server encodes many small frames concurrently already.
    Imf::RgbaOutputFile file(stream, header, Imf::WRITE_RGB, 0);
    file.setFrameBuffer(pixels.data(), 1, std::size_t{width});
    file.writePixels(static_cast<int>(height));
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("exr: cannot encode: ") + e.what());
  }
  return stream.take();
}

LinearImage decodeExr(std::string_view bytes, std::optional<ImageSize> expected) {
  MemoryIStream stream(bytes);
  std::optional<Imf::RgbaInputFile> file;
  try {
    file.emplace(stream, 1);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("exr: cannot decode: ") + e.what());
  }
  const Imath::Box2i dw = file->dataWindow();
  const std::int64_t w = std::int64_t{dw.max.x} - dw.min.x + 1, h = std::int64_t{dw.max.y} - dw.min.y + 1;
  const ImageSize size = detail::checkDecodedSize("exr", w, h, expected);
  std::vector<Imf::Rgba> pixels(std::size_t{size.width} * size.height);
  try {
    // The frame buffer is addressed by absolute data-window coordinates.
    const std::ptrdiff_t origin = -static_cast<std::ptrdiff_t>(dw.min.x) - static_cast<std::ptrdiff_t>(dw.min.y) * w;
    file->setFrameBuffer(pixels.data() + origin, 1, std::size_t{size.width});
    file->readPixels(dw.min.y, dw.max.y);
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("exr: cannot decode: ") + e.what());
  }
  LinearImage image{size.width, size.height, {}};
  image.rgb.reserve(pixels.size() * 3);
  for (const Imf::Rgba& p : pixels) {
    image.rgb.insert(image.rgb.end(), {static_cast<float>(p.r), static_cast<float>(p.g), static_cast<float>(p.b)});
  }
  return image;
}

}  // namespace haarcast::wire
