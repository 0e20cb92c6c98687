// Radiance RGBE (.hdr/.pic) reading (image.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "haarcast/io/image.h"
#include "image_common.h"

namespace haarcast::io {
namespace {

using detail::ByteCursor;
using detail::checkFileDimensions;
using detail::fail;
using detail::growPixels;
using detail::readFileBytes;

// ---------------------------------------------------------------- Radiance
// Greg Ward, "Real Pixels", Graphics Gems II (1991), and the Radiance file
// format notes (radsite.lbl.gov, "The RADIANCE Picture File Format"): a text
// header ended by a blank line, a resolution line, then one record per
// scanline of 4-byte RGBE pixels, flat, old-style run-length or new-style
// (per-channel) run-length encoded.


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


}  // namespace

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


}  // namespace haarcast::io
