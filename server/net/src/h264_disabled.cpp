// The H.264 encoder of a build without libavcodec (configured with
// -DHAARCAST_H264=OFF, for machines that carry no codec libraries): a
// session that asks for H.264 is refused with the reason; every other
// encoding works as in a full build.
#include <stdexcept>

#include "haarcast/net/h264_encoder.h"

namespace haarcast::net {

struct H264Encoder::Codec {};

H264Encoder::H264Encoder(const H264Settings& settings) : settings_(settings) {
  validateH264Settings(settings_);
  throw std::runtime_error("h264: this haarcast was built without libavcodec (-DHAARCAST_H264=OFF); "
                           "choose jpeg, png, raw or exr");
}
H264Encoder::~H264Encoder() = default;
void H264Encoder::open() {}
void H264Encoder::reconfigure(const H264Settings& settings) { validateH264Settings(settings); }
H264AccessUnit H264Encoder::encode(const std::vector<std::uint8_t>&, int, int) {
  throw std::runtime_error("h264: this haarcast was built without libavcodec (-DHAARCAST_H264=OFF)");
}

}  // namespace haarcast::net
