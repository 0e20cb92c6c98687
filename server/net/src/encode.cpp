#include "haarcast/net/encode.h"

#include <stdexcept>

#include "haarcast/wire/exr_codec.h"
#include "haarcast/wire/frame_codec.h"

namespace haarcast::net {
namespace {

// The renderer's sizes are ints; a negative one must not wrap to a size the
// codec takes: it becomes 0, which every codec refuses by name.
std::uint32_t side(int value) { return value > 0 ? static_cast<std::uint32_t>(value) : 0; }

}  // namespace

std::string encodeFrame(FrameEncoding encoding, const std::vector<std::uint8_t>& rgba8, int width, int height,
                        const io::RgbImage& linear, int jpegQuality) {
  switch (encoding) {
    case FrameEncoding::Jpeg: return wire::encodeJpeg(rgba8, side(width), side(height), jpegQuality);
    case FrameEncoding::Png: return wire::encodePng(rgba8, side(width), side(height));
    case FrameEncoding::RawRgba8: return wire::encodeRaw(rgba8, side(width), side(height));
    case FrameEncoding::Exr: return wire::encodeExr(linear.rgb, side(linear.width), side(linear.height));
    case FrameEncoding::H264:
      throw std::logic_error("encodeFrame: H.264 frames depend on the ones before; the session's H264Encoder encodes them");
  }
  throw std::runtime_error("encodeFrame: unknown encoding");
}

}  // namespace haarcast::net
