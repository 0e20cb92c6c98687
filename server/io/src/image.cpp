#include "haarcast/io/image.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include <ImfArray.h>
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfRgbaFile.h>
#include <ImfTileDescription.h>
#include <png.h>

#include "image_common.h"

namespace haarcast::io {
namespace {

using detail::ByteCursor;
using detail::checkFileDimensions;
using detail::checkImage;
using detail::fail;
using detail::growPixels;
using detail::readFileBytes;
using detail::sizeText;

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// ---------------------------------------------------------------- PFM
// The PFM format (Paul Debevec's HDRShop notes, also netpbm's pfm(5)): "PF"
// or "Pf", width, height, scale as ASCII separated by whitespace, exactly one
// whitespace byte, then float rows from the bottom of the image to the top.

bool isSpace(std::uint8_t b) { return b == ' ' || b == '\t' || b == '\n' || b == '\r'; }

std::string nextToken(ByteCursor& c) {
  while (c.pos != c.end && isSpace(*c.pos)) ++c.pos;
  const std::uint8_t* start = c.pos;
  while (c.pos != c.end && !isSpace(*c.pos) && c.pos - start < 64) ++c.pos;
  return std::string(reinterpret_cast<const char*>(start), static_cast<std::size_t>(c.pos - start));
}

bool parseInteger(const std::string& token, long long& value) {
  if (token.empty() || token.size() > 18) return false;
  char* endp = nullptr;
  value = std::strtoll(token.c_str(), &endp, 10);
  return endp == token.c_str() + token.size();
}

// ---------------------------------------------------------------- OpenEXR

// A band of rows holds about this many bytes of float RGB (at least one
// chunk's rows), so that the image grows in steps the file has delivered.
constexpr std::size_t kExrBandBytes = std::size_t{8} << 20;

// Scanlines per chunk for each compression (OpenEXR "Technical Introduction",
// the table of compression methods; ImfCompressor.cpp's numScanLines).
int exrLinesPerChunk(Imf::Compression compression) {
  switch (compression) {
    case Imf::ZIP_COMPRESSION:
    case Imf::PXR24_COMPRESSION:
      return 16;
    case Imf::PIZ_COMPRESSION:
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION:
    case Imf::DWAA_COMPRESSION:
      return 32;
    case Imf::DWAB_COMPRESSION:
      return 256;
    default:  // none, RLE, ZIPS
      return 1;
  }
}

// Every chunk of a file has an 8-byte entry in the offset table and, in the
// chunk itself, at least its coordinates and data size (8 bytes for a
// scanline chunk, 20 for a tile: OpenEXR "File Layout"). A data window
// promising more chunks than the file has bytes for is refused before any
// pixel is allocated.
void checkExrChunksFit(const std::string& path, const Imf::Header& header, long long width, long long height) {
  std::error_code ec;
  const std::uintmax_t fileBytes = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot read its size: " + ec.message());
  unsigned long long chunks = 0;
  std::size_t chunkBytes = 0;
  if (header.hasTileDescription()) {
    const Imf::TileDescription& tiles = header.tileDescription();
    const unsigned long long tw = std::max(1u, tiles.xSize), th = std::max(1u, tiles.ySize);
    chunks = ((static_cast<unsigned long long>(width) + tw - 1) / tw) *
             ((static_cast<unsigned long long>(height) + th - 1) / th);
    chunkBytes = 8 + 20;
  } else {
    const auto lines = static_cast<unsigned long long>(exrLinesPerChunk(header.compression()));
    chunks = (static_cast<unsigned long long>(height) + lines - 1) / lines;
    chunkBytes = 8 + 8;
  }
  if (chunks > fileBytes / chunkBytes) {
    fail(path, "truncated file: a " + sizeText(width, height) + " data window needs " + std::to_string(chunks) +
                   " chunks of at least " + std::to_string(chunkBytes) + " bytes each, and the file has " +
                   std::to_string(fileBytes) + " bytes");
  }
}

}  // namespace

std::uint8_t encodeSrgb(double linear) {
  if (!(linear > 0.0)) return 0;  // also NaN
  if (linear >= 1.0) return 255;
  // IEC 61966-2-1 transfer function.
  const double s = linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
  return static_cast<std::uint8_t>(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
}

RgbImage makeImage(int width, int height) {
  if (width <= 0 || height <= 0 || width > kMaxImageDimension || height > kMaxImageDimension ||
      static_cast<std::size_t>(width) * static_cast<std::size_t>(height) > kMaxImagePixels) {
    throw std::invalid_argument("makeImage: bad dimensions " + sizeText(width, height));
  }
  RgbImage image;
  image.width = width;
  image.height = height;
  image.rgb.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3, 0.0f);
  return image;
}

// ---------------------------------------------------------------- OpenEXR

RgbImage readExr(const std::string& path) {
  {
    // Our own first look, so that a missing, empty or foreign file gets a
    // plain message. The magic number is 20000630 little-endian
    // (OpenEXR "File Layout": 0x76, 0x2f, 0x31, 0x01).
    if (auto why = whyNotRegularFile(path)) fail(path, "cannot open for reading: " + *why);
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, "cannot open for reading");
    std::array<char, 4> magic{};
    in.read(magic.data(), 4);
    if (in.gcount() == 0) fail(path, "empty file");
    if (in.gcount() < 4 || static_cast<std::uint8_t>(magic[0]) != 0x76 || static_cast<std::uint8_t>(magic[1]) != 0x2f ||
        static_cast<std::uint8_t>(magic[2]) != 0x31 || static_cast<std::uint8_t>(magic[3]) != 0x01) {
      fail(path, "not an OpenEXR file (bad magic number)");
    }
  }
  // OpenEXR sizes its offset table and line buffers from the header's data
  // window while it opens the file; with these limits set it refuses an
  // absurd window before allocating for it (Imf::Header::sanityCheck).
  static const bool limitsSet = [] {
    Imf::Header::setMaxImageSize(kMaxImageDimension, kMaxImageDimension);
    Imf::Header::setMaxTileSize(kMaxImageDimension, kMaxImageDimension);
    return true;
  }();
  (void)limitsSet;
  std::unique_ptr<Imf::InputFile> file;
  try {
    file = std::make_unique<Imf::InputFile>(path.c_str());
  } catch (const std::exception& e) {
    fail(path, std::string("cannot read OpenEXR header: ") + e.what());
  }
  const Imath::Box2i dw = file->header().dataWindow();
  const long long width = static_cast<long long>(dw.max.x) - dw.min.x + 1;
  const long long height = static_cast<long long>(dw.max.y) - dw.min.y + 1;
  checkFileDimensions(path, width, height);
  checkExrChunksFit(path, file->header(), width, height);

  const Imf::ChannelList& channels = file->header().channels();
  const auto full = [&](const char* name) {
    const Imf::Channel* ch = channels.findChannel(name);
    return ch != nullptr && ch->xSampling == 1 && ch->ySampling == 1;
  };
  const bool rgb = full("R") && full("G") && full("B");
  const bool luminance = channels.findChannel("Y") != nullptr;
  const bool chroma = channels.findChannel("RY") != nullptr || channels.findChannel("BY") != nullptr;
  const bool grey = !rgb && full("Y") && !chroma;
  const bool lumaChroma = !rgb && luminance && channels.findChannel("RY") != nullptr &&
                          channels.findChannel("BY") != nullptr;
  if (!rgb && !grey && !lumaChroma) {
    std::string names;
    for (auto it = channels.begin(); it != channels.end(); ++it) names += std::string(names.empty() ? "" : ", ") + it.name();
    fail(path, "unsupported EXR channel layout (channels: " + (names.empty() ? std::string("none") : names) +
                   "; expected R, G, B, or Y alone, or Y, RY, BY)");
  }

  // Read a band of rows at a time, the image growing with each (growPixels):
  // a file whose chunks are missing or corrupt fails having allocated no
  // more than it delivered.
  RgbImage image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  const std::size_t rowFloats = static_cast<std::size_t>(width) * 3;
  const std::size_t totalFloats = rowFloats * static_cast<std::size_t>(height);
  // Whole chunks per band, so that no chunk is decoded twice.
  const int chunkRows = file->header().hasTileDescription()
                            ? static_cast<int>(std::max(1u, file->header().tileDescription().ySize))
                            : exrLinesPerChunk(file->header().compression());
  const std::size_t chunkBytes = rowFloats * sizeof(float) * static_cast<std::size_t>(chunkRows);
  const int bandRows = static_cast<int>(std::min<long long>(
      height, chunkRows * static_cast<long long>(std::max<std::size_t>(1, kExrBandBytes / chunkBytes))));
  try {
    if (lumaChroma) {
      // Subsampled luminance-chroma needs OpenEXR's own reconstruction, which
      // the RGBA interface does (in half precision, the precision such files have).
      file.reset();
      Imf::RgbaInputFile rgbaFile(path.c_str());
      Imf::Array2D<Imf::Rgba> band(bandRows, width);
      for (long long y0 = dw.min.y; y0 <= dw.max.y; y0 += bandRows) {
        const int top = static_cast<int>(y0);
        const int y1 = static_cast<int>(std::min<long long>(dw.max.y, y0 + bandRows - 1));
        const Imath::Box2i bandWindow(Imath::V2i(dw.min.x, top), Imath::V2i(dw.max.x, y1));
        rgbaFile.setFrameBuffer(Imf::ComputeBasePointer(&band[0][0], bandWindow), 1, static_cast<std::size_t>(width));
        rgbaFile.readPixels(top, y1);
        growPixels(image.rgb, rowFloats * static_cast<std::size_t>(y1 - top + 1), totalFloats);
        for (int y = top; y <= y1; ++y) {
          for (int x = 0; x < image.width; ++x) {
            const Imf::Rgba& px = band[y - top][x];
            float* out = &image.rgb[image.index(y - dw.min.y, x)];
            out[0] = px.r;
            out[1] = px.g;
            out[2] = px.b;
          }
        }
      }
      return image;
    }
    // OpenEXR converts half and uint channels to the FLOAT slices we ask for.
    const std::size_t xStride = 3 * sizeof(float);
    const std::size_t yStride = xStride * static_cast<std::size_t>(width);
    // y0 in long long: a data window may end at INT_MAX.
    for (long long y0 = dw.min.y; y0 <= dw.max.y; y0 += bandRows) {
      const int top = static_cast<int>(y0);
      const int y1 = static_cast<int>(std::min<long long>(dw.max.y, y0 + bandRows - 1));
      growPixels(image.rgb, rowFloats * static_cast<std::size_t>(y1 - top + 1), totalFloats);
      float* first = &image.rgb[image.index(top - dw.min.y, 0)];
      const Imath::Box2i bandWindow(Imath::V2i(dw.min.x, top), Imath::V2i(dw.max.x, y1));
      Imf::FrameBuffer fb;
      if (rgb) {
        fb.insert("R", Imf::Slice::Make(Imf::FLOAT, first + 0, bandWindow, xStride, yStride));
        fb.insert("G", Imf::Slice::Make(Imf::FLOAT, first + 1, bandWindow, xStride, yStride));
        fb.insert("B", Imf::Slice::Make(Imf::FLOAT, first + 2, bandWindow, xStride, yStride));
      } else {
        fb.insert("Y", Imf::Slice::Make(Imf::FLOAT, first, bandWindow, xStride, yStride));
      }
      file->setFrameBuffer(fb);
      file->readPixels(top, y1);
    }
  } catch (const std::exception& e) {
    fail(path, std::string("cannot read OpenEXR pixels (truncated or corrupt file?): ") + e.what());
  }
  if (grey) {
    for (std::size_t p = 0; p < image.rgb.size(); p += 3) image.rgb[p + 1] = image.rgb[p + 2] = image.rgb[p];
  }
  return image;
}

void writeExr(const std::string& path, const RgbImage& image) {
  checkImage(path, image);
  try {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    header.channels().insert("R", Imf::Channel(Imf::FLOAT));
    header.channels().insert("G", Imf::Channel(Imf::FLOAT));
    header.channels().insert("B", Imf::Channel(Imf::FLOAT));
    Imf::OutputFile file(path.c_str(), header);
    const std::size_t xStride = 3 * sizeof(float);
    const std::size_t yStride = xStride * static_cast<std::size_t>(image.width);
    const Imath::V2i origin(0, 0);
    Imf::FrameBuffer fb;
    for (int ch = 0; ch < 3; ++ch) {
      const char* names[] = {"R", "G", "B"};
      fb.insert(names[ch], Imf::Slice::Make(Imf::FLOAT, image.rgb.data() + ch, origin, image.width,
                                            image.height, xStride, yStride));
    }
    file.setFrameBuffer(fb);
    file.writePixels(image.height);
  } catch (const std::exception& e) {
    fail(path, std::string("cannot write OpenEXR file: ") + e.what());
  }
}

// ---------------------------------------------------------------- PFM

RgbImage readPfm(const std::string& path) {
  const std::vector<std::uint8_t> bytes = readFileBytes(path);
  ByteCursor c{bytes.data(), bytes.data() + bytes.size()};
  const std::string magic = nextToken(c);
  if (magic != "PF" && magic != "Pf") fail(path, "not a PFM file (the magic must be PF or Pf)");
  const int channels = magic == "PF" ? 3 : 1;
  long long width = 0, height = 0;
  const std::string w = nextToken(c), h = nextToken(c);
  if (!parseInteger(w, width) || !parseInteger(h, height)) {
    fail(path, "bad PFM dimensions \"" + w + " " + h + "\"");
  }
  checkFileDimensions(path, width, height);
  const std::string scaleToken = nextToken(c);
  char* endp = nullptr;
  const double scale = std::strtod(scaleToken.c_str(), &endp);
  if (scaleToken.empty() || endp != scaleToken.c_str() + scaleToken.size() || scale == 0.0 || !std::isfinite(scale)) {
    fail(path, "bad PFM scale \"" + scaleToken + "\"");
  }
  // Exactly one whitespace byte separates the header from the raster.
  if (c.pos == c.end || !isSpace(*c.pos)) fail(path, "truncated PFM header");
  ++c.pos;

  const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
                            static_cast<std::size_t>(channels);
  if (c.left() / sizeof(float) < count) {
    fail(path, "truncated pixel data: " + sizeText(width, height) + " pixels of " + std::to_string(channels) +
                   " floats need " + std::to_string(count * sizeof(float)) + " bytes, and " +
                   std::to_string(c.left()) + " bytes remain");
  }
  const bool fileLittle = scale < 0.0;
  const bool swap = fileLittle != (std::endian::native == std::endian::little);
  RgbImage image = makeImage(static_cast<int>(width), static_cast<int>(height));
  for (int line_i = 0; line_i < image.height; ++line_i) {
    const int row = image.height - 1 - line_i;  // bottom to top
    for (int x = 0; x < image.width; ++x) {
      for (int ch = 0; ch < channels; ++ch) {
        std::uint32_t bits;
        std::memcpy(&bits, c.pos, 4);
        c.pos += 4;
        if (swap) bits = __builtin_bswap32(bits);
        float v;
        std::memcpy(&v, &bits, 4);
        if (channels == 1) {
          image.at(row, x, 0) = image.at(row, x, 1) = image.at(row, x, 2) = v;
        } else {
          image.at(row, x, ch) = v;
        }
      }
    }
  }
  return image;
}

void writePfm(const std::string& path, const RgbImage& image) {
  checkImage(path, image);
  std::ofstream out(path, std::ios::binary);
  if (!out) fail(path, "cannot open for writing");
  out << "PF\n" << image.width << ' ' << image.height << "\n-1.0\n";
  std::vector<std::uint8_t> row(static_cast<std::size_t>(image.width) * 3 * sizeof(float));
  for (int line_i = 0; line_i < image.height; ++line_i) {
    const float* src = &image.rgb[image.index(image.height - 1 - line_i, 0)];
    for (std::size_t k = 0; k < static_cast<std::size_t>(image.width) * 3; ++k) {
      std::uint32_t bits;
      std::memcpy(&bits, &src[k], 4);
      if constexpr (std::endian::native == std::endian::big) bits = __builtin_bswap32(bits);
      std::memcpy(&row[k * 4], &bits, 4);
    }
    out.write(reinterpret_cast<const char*>(row.data()), static_cast<std::streamsize>(row.size()));
  }
  if (!out) fail(path, "write error");
}

// ---------------------------------------------------------------- PNG

namespace {

// libpng's simplified API reports errors in image.message instead of
// longjmp-ing through C++ frames. An 8-bit non-linear format is written
// with an sRGB chunk.
void writePngPixels(const std::string& path, int width, int height, png_uint_32 format, const std::uint8_t* pixels) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(width);
  png.height = static_cast<png_uint_32>(height);
  png.format = format;
  if (png_image_write_to_file(&png, path.c_str(), 0, pixels, 0, nullptr) == 0) {
    const std::string message = png.message;
    png_image_free(&png);
    fail(path, "cannot write PNG: " + message);
  }
}

}  // namespace

void writePng(const std::string& path, const RgbImage& image, double exposureStops) {
  checkImage(path, image);
  const double gain = std::exp2(exposureStops);
  std::vector<std::uint8_t> pixels(image.rgb.size());
  for (std::size_t k = 0; k < pixels.size(); ++k) pixels[k] = encodeSrgb(image.rgb[k] * gain);
  writePngPixels(path, image.width, image.height, PNG_FORMAT_RGB, pixels.data());
}

void writePngRgba8(const std::string& path, const std::vector<std::uint8_t>& rgba8, int width, int height) {
  if (width <= 0 || height <= 0 || rgba8.size() != 4 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    fail(path, "RGBA8 image of " + std::to_string(rgba8.size()) + " bytes does not match " + sizeText(width, height));
  }
  writePngPixels(path, width, height, PNG_FORMAT_RGBA, rgba8.data());
}

// ---------------------------------------------------------------- dispatch

RgbImage readImage(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".exr") return readExr(path);
  if (ext == ".hdr" || ext == ".pic" || ext == ".rgbe") return readRadianceHdr(path);
  if (ext == ".pfm") return readPfm(path);
  fail(path, "unknown image extension \"" + ext + "\" (expected .exr, .hdr, .pic, .rgbe or .pfm)");
}

}  // namespace haarcast::io
