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

namespace haarcast::io {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

std::string sizeText(long long width, long long height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// The one size check of every reader, done before any pixel is allocated.
void checkFileDimensions(const std::string& path, long long width, long long height) {
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
void checkImage(const std::string& path, const RgbImage& image) {
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
void growPixels(std::vector<float>& pixels, std::size_t more, std::size_t total) {
  const std::size_t needed = pixels.size() + more;
  if (needed > pixels.capacity()) pixels.reserve(std::min(total, std::max(needed, 2 * pixels.capacity())));
  pixels.resize(needed);
}

std::vector<std::uint8_t> readFileBytes(const std::string& path) {
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

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// ---------------------------------------------------------------- Radiance
// Greg Ward, "Real Pixels", Graphics Gems II (1991), and the Radiance file
// format notes (radsite.lbl.gov, "The RADIANCE Picture File Format"): a text
// header ended by a blank line, a resolution line, then one record per
// scanline of 4-byte RGBE pixels, flat, old-style run-length or new-style
// (per-channel) run-length encoded.

// A cursor over the file's bytes that never reads past the end.
struct ByteCursor {
  const std::uint8_t* pos;
  const std::uint8_t* end;
  std::size_t left() const { return static_cast<std::size_t>(end - pos); }
};

// One header line without its '\n' (and a trailing '\r', for files that went
// through Windows tools); false at the end of the data.
bool nextLine(ByteCursor& c, std::string& line) {
  if (c.pos == c.end) return false;
  const std::uint8_t* nl = std::find(c.pos, c.end, std::uint8_t{'\n'});
  if (nl == c.end) return false;
  line.assign(reinterpret_cast<const char*>(c.pos), static_cast<std::size_t>(nl - c.pos));
  if (!line.empty() && line.back() == '\r') line.pop_back();
  c.pos = nl + 1;
  return true;
}

// Ward's colr_color: the mantissa byte's centre, (m + ½)·2^(e−136); e = 0 is black.
inline void rgbeToFloat(const std::uint8_t* p, double scale, float* out) {
  if (p[3] == 0) {
    out[0] = out[1] = out[2] = 0.0f;
    return;
  }
  const double f = std::ldexp(1.0, static_cast<int>(p[3]) - (128 + 8)) * scale;
  for (int ch = 0; ch < 3; ++ch) out[ch] = static_cast<float>((p[ch] + 0.5) * f);
}

// Decodes one scanline of `width` RGBE pixels into `scan` (4 bytes a pixel).
// `line` is the scanline's index in file order, for messages.
void readRgbeScanline(const std::string& path, ByteCursor& c, int width, int line, int lines,
                      std::vector<std::uint8_t>& scan) {
  const auto truncated = [&] {
    fail(path, "truncated scanline " + std::to_string(line) + " of " + std::to_string(lines));
  };
  const auto corrupt = [&](const std::string& what) {
    fail(path, "corrupt scanline " + std::to_string(line) + ": " + what);
  };
  if (c.left() < 4) truncated();
  const std::uint8_t* head = c.pos;
  // New-style RLE (Radiance ≥ 2.0): marker 2, 2, then the width as a 15-bit
  // big-endian number; each of the four channels follows as runs (count > 128:
  // count − 128 copies of one byte) and literals (count bytes). Only widths in
  // [8, 0x7fff] may use it.
  if (width >= 8 && width <= 0x7fff && head[0] == 2 && head[1] == 2 && (head[2] & 0x80) == 0) {
    const int encodedWidth = (head[2] << 8) | head[3];
    if (encodedWidth != width) {
      corrupt("run-length header gives width " + std::to_string(encodedWidth) + ", expected " +
              std::to_string(width));
    }
    c.pos += 4;
    for (int ch = 0; ch < 4; ++ch) {
      int x = 0;
      while (x < width) {
        if (c.left() < 1) truncated();
        int count = *c.pos++;
        if (count > 128) {
          count -= 128;
          if (x + count > width) corrupt("run overruns the scanline");
          if (c.left() < 1) truncated();
          const std::uint8_t value = *c.pos++;
          for (int k = 0; k < count; ++k) scan[static_cast<std::size_t>(x + k) * 4 + static_cast<std::size_t>(ch)] = value;
        } else {
          if (count == 0) corrupt("zero-length literal");
          if (x + count > width) corrupt("literal overruns the scanline");
          if (c.left() < static_cast<std::size_t>(count)) truncated();
          for (int k = 0; k < count; ++k) scan[static_cast<std::size_t>(x + k) * 4 + static_cast<std::size_t>(ch)] = *c.pos++;
        }
        x += count;
      }
    }
    return;
  }
  // Flat pixels, with the original format's run-length escape: a pixel
  // (1, 1, 1, n) repeats the previous pixel n << shift times, and consecutive
  // escapes shift by 8 more bits each (Radiance's oldreadcolrs).
  int x = 0;
  int shift = 0;
  while (x < width) {
    if (c.left() < 4) truncated();
    const std::uint8_t* p = c.pos;
    c.pos += 4;
    if (p[0] == 1 && p[1] == 1 && p[2] == 1) {
      if (x == 0) corrupt("run-length escape before the first pixel");
      if (shift > 16) corrupt("run-length escape too long");
      const long long count = static_cast<long long>(p[3]) << shift;
      if (x + count > width) corrupt("run overruns the scanline");
      for (long long k = 0; k < count; ++k, ++x) {
        std::memcpy(&scan[static_cast<std::size_t>(x) * 4], &scan[static_cast<std::size_t>(x - 1) * 4], 4);
      }
      shift += 8;
    } else {
      std::memcpy(&scan[static_cast<std::size_t>(x) * 4], p, 4);
      ++x;
      shift = 0;
    }
  }
}

// The fewest bytes a scanline of `width` pixels can take: a flat pixel (4),
// then old-style run escapes of up to 255 << 0, 255 << 8, 255 << 16 copies
// (4 bytes each). New-style runs never do better (a 4-byte marker, then 2
// bytes per run of ≤ 127 per channel: 12 bytes at least for width ≥ 8).
std::size_t minRgbeScanlineBytes(long long width) {
  if (width <= 1) return 4;
  if (width <= 1 + 255) return 8;
  if (width <= 1 + 255 + (255 << 8)) return 12;
  return 16;
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

// ---------------------------------------------------------------- Radiance

RgbImage readRadianceHdr(const std::string& path) {
  const std::vector<std::uint8_t> bytes = readFileBytes(path);
  ByteCursor c{bytes.data(), bytes.data() + bytes.size()};

  // Header: the magic line, "NAME=value" and comment lines, a blank line.
  std::string line;
  const bool haveFirst = nextLine(c, line);
  if (!haveFirst || (line != "#?RADIANCE" && line != "#?RGBE")) {
    fail(path, "not a Radiance file (the first line must be #?RADIANCE or #?RGBE)");
  }
  double exposure = 1.0;
  bool ended = false;
  while (nextLine(c, line)) {
    if (line.empty()) {
      ended = true;
      break;
    }
    if (line.rfind("FORMAT=", 0) == 0) {
      const std::string format = line.substr(7);
      if (format != "32-bit_rle_rgbe") {
        fail(path, "unsupported Radiance FORMAT=" + format + " (only 32-bit_rle_rgbe is read)");
      }
    } else if (line.rfind("EXPOSURE=", 0) == 0) {
      char* endp = nullptr;
      const double e = std::strtod(line.c_str() + 9, &endp);
      if (endp == line.c_str() + 9 || !(e > 0.0) || !std::isfinite(e)) fail(path, "bad header line \"" + line + "\"");
      exposure *= e;  // EXPOSURE lines are cumulative
    }
  }
  if (!ended) fail(path, "truncated header (no blank line before the resolution line)");

  // Resolution line: "-Y h +X w" is the standard top-to-bottom, left-to-right
  // order; "+Y" stores rows bottom to top and "-X" right to left. The
  // transposed orders ("+X w -Y h", …) are rare and not read.
  if (!nextLine(c, line)) fail(path, "truncated file: no resolution line");
  std::istringstream res(line);
  std::string yAxis, xAxis, rest;
  long long height = 0, width = 0;
  if (!(res >> yAxis >> height >> xAxis >> width) || (res >> rest)) {
    fail(path, "bad resolution line \"" + line + "\"");
  }
  if ((yAxis != "-Y" && yAxis != "+Y") || (xAxis != "+X" && xAxis != "-X")) {
    fail(path, "unsupported resolution line \"" + line + "\" (expected -Y h +X w, or its flips)");
  }
  checkFileDimensions(path, width, height);
  // A header promising more scanlines than the rest of the file can hold is
  // refused before anything is allocated for them.
  const std::size_t minScanline = minRgbeScanlineBytes(width);
  if (c.left() / minScanline < static_cast<std::size_t>(height)) {
    fail(path, "truncated file: " + std::to_string(height) + " scanlines of " + std::to_string(width) +
                   " pixels need at least " + std::to_string(static_cast<std::size_t>(height) * minScanline) +
                   " bytes, and " + std::to_string(c.left()) + " bytes of pixel data remain");
  }

  // The pixels grow with the decoded scanlines (growPixels), in file order;
  // a "+Y" file's rows are put top-down at the end.
  RgbImage image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  const std::size_t rowFloats = static_cast<std::size_t>(width) * 3;
  const std::size_t totalFloats = rowFloats * static_cast<std::size_t>(height);
  const bool bottomUp = yAxis == "+Y";
  const bool rightToLeft = xAxis == "-X";
  std::vector<std::uint8_t> scan(static_cast<std::size_t>(width) * 4);
  const double scale = 1.0 / exposure;
  for (int line_i = 0; line_i < image.height; ++line_i) {
    readRgbeScanline(path, c, image.width, line_i, image.height, scan);
    growPixels(image.rgb, rowFloats, totalFloats);
    for (int x = 0; x < image.width; ++x) {
      const int col = rightToLeft ? image.width - 1 - x : x;
      rgbeToFloat(&scan[static_cast<std::size_t>(x) * 4], scale, &image.rgb[image.index(line_i, col)]);
    }
  }
  if (bottomUp) {
    for (int top = 0, bottom = image.height - 1; top < bottom; ++top, --bottom) {
      std::swap_ranges(image.rgb.begin() + static_cast<std::ptrdiff_t>(image.index(top, 0)),
                       image.rgb.begin() + static_cast<std::ptrdiff_t>(image.index(top, 0) + rowFloats),
                       image.rgb.begin() + static_cast<std::ptrdiff_t>(image.index(bottom, 0)));
    }
  }
  return image;
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
