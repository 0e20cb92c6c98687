// The CLI client's H.264 decoder in a build without libavcodec (configured
// with -DHAARCAST_H264=OFF): asking for H.264 frames is refused with the
// reason; the other encodings decode as in a full build.
#include <stdexcept>

#include "haarcast/client/h264_decoder.h"

namespace haarcast::client {

struct H264Decoder::Codec {};

H264Decoder::H264Decoder() {
  throw std::runtime_error("h264: this build has no libavcodec (-DHAARCAST_H264=OFF); choose jpeg, png, raw or exr");
}
H264Decoder::~H264Decoder() = default;
wire::Rgba8Image H264Decoder::decode(std::span<const std::uint8_t>, std::uint32_t, std::uint32_t) {
  throw std::runtime_error("h264: this build has no libavcodec (-DHAARCAST_H264=OFF)");
}

}  // namespace haarcast::client
