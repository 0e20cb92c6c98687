// The CLI client's view of decoded frames: a session's FrameDecoder (H.264
// in order through h264_decoder.h, every other encoding through the wire
// library's decodeFrame, haarcast/wire/frame_decode.h), the statistics of
// the not-blank and clipping checks, and PAM for writing raw frames as
// viewable files. PNG for decoded H.264 frames is wire::encodePng.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "haarcast/proto/haarcast.pb.h"
#include "haarcast/wire/image.h"

namespace haarcast::client {

class H264Decoder;

// The frames of one session, in order: H.264 through the session's own
// decoder (it keeps the reference pictures between frames, so every H.264
// frame must pass through it, also those not inspected), every other
// encoding through wire::decodeFrame. `width`/`height` are what the Frame
// message claims; throws std::runtime_error as wire::decodeFrame does.
class FrameDecoder {
 public:
  FrameDecoder();
  ~FrameDecoder();
  FrameDecoder(const FrameDecoder&) = delete;
  FrameDecoder& operator=(const FrameDecoder&) = delete;

  wire::Rgba8Image decode(v1::Encoding encoding, std::span<const std::uint8_t> data, std::uint32_t width,
                          std::uint32_t height);

 private:
  std::unique_ptr<H264Decoder> h264_;  // made at the first H.264 frame
};

struct PixelStats {
  double meanLuma = 0.0;    // Rec. 709 luma of the 8-bit sRGB values, 0..255
  double stddevLuma = 0.0;  // over all pixels
  double clippedFraction = 0.0;  // of the pixels with a channel at 255 (blown out)
};
PixelStats pixelStats(const wire::Rgba8Image& image);

// A frame is blank when its luma barely varies: a solid clear colour, an
// all-black failed render. A frame that shows any object over the sky varies
// by tens of levels. The threshold is one 8-bit level of standard deviation.
inline constexpr double kBlankStddevLuma = 1.0;
inline bool isBlank(const PixelStats& s) { return s.stddevLuma < kBlankStddevLuma; }

// netpbm PAM (P7, RGB_ALPHA) bytes of an RGBA8 image: how raw frames are
// written to disk.
std::vector<std::uint8_t> encodePam(const wire::Rgba8Image& image);

}  // namespace haarcast::client
