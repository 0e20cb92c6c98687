#include "haarcast/client/frame_image.h"

#include <cmath>
#include <string_view>

#include "haarcast/client/h264_decoder.h"
#include "haarcast/wire/frame_decode.h"

namespace haarcast::client {

FrameDecoder::FrameDecoder() = default;
FrameDecoder::~FrameDecoder() = default;

wire::Rgba8Image FrameDecoder::decode(v1::Encoding encoding, std::span<const std::uint8_t> data, std::uint32_t width,
                                      std::uint32_t height) {
  if (encoding != v1::ENCODING_H264) {
    const std::string_view bytes(reinterpret_cast<const char*>(data.data()), data.size());
    return wire::decodeFrame(encoding, bytes, width, height);
  }
  if (!h264_) h264_ = std::make_unique<H264Decoder>();
  return h264_->decode(data, width, height);
}

PixelStats pixelStats(const wire::Rgba8Image& image) {
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

std::vector<std::uint8_t> encodePam(const wire::Rgba8Image& image) {
  const std::string header = "P7\nWIDTH " + std::to_string(image.width) + "\nHEIGHT " + std::to_string(image.height) +
                             "\nDEPTH 4\nMAXVAL 255\nTUPLTYPE RGB_ALPHA\nENDHDR\n";
  std::vector<std::uint8_t> out(header.begin(), header.end());
  out.insert(out.end(), image.pixels.begin(), image.pixels.end());
  return out;
}

}  // namespace haarcast::client
