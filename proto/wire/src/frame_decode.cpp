#include "haarcast/wire/frame_decode.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "haarcast/wire/exr_codec.h"
#include "haarcast/wire/frame_codec.h"
#include "size_checks.h"

namespace haarcast::wire {

std::uint8_t linearToSrgb8(float linear) {
  if (std::isnan(linear)) return 0;
  const double v = std::clamp(static_cast<double>(linear), 0.0, 1.0);
  const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<std::uint8_t>(std::lround(s * 255.0));
}

Rgba8Image decodeFrame(v1::Encoding encoding, std::string_view data, std::uint32_t width, std::uint32_t height) {
  if (width == 0 || height == 0) {
    throw std::runtime_error("frame has no size (" + detail::sizeText(width, height) + ")");
  }
  const ImageSize size{width, height};
  switch (encoding) {
    case v1::ENCODING_JPEG: return decodeJpeg(data, size);
    case v1::ENCODING_PNG: return decodePng(data, size);
    case v1::ENCODING_RAW_RGBA8: return decodeRaw(data, size);
    case v1::ENCODING_EXR: {
      const LinearImage linear = decodeExr(data, size);
      Rgba8Image out{width, height, std::vector<std::uint8_t>(std::size_t{width} * height * 4)};
      for (std::size_t i = 0; i < std::size_t{width} * height; ++i) {
        out.pixels[4 * i] = linearToSrgb8(linear.rgb[3 * i]);
        out.pixels[4 * i + 1] = linearToSrgb8(linear.rgb[3 * i + 1]);
        out.pixels[4 * i + 2] = linearToSrgb8(linear.rgb[3 * i + 2]);
        out.pixels[4 * i + 3] = 255;
      }
      return out;
    }
    case v1::ENCODING_H264:
      throw std::runtime_error("h264: frames depend on the ones before them: decode them in order with the "
                               "session's FrameDecoder");
    default:
      throw std::runtime_error("frame has unknown encoding " + std::to_string(static_cast<int>(encoding)));
  }
}

}  // namespace haarcast::wire
