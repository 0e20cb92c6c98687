// Decoding a Frame's payload back to pixels, for the not-blank check and for
// writing raw frames as viewable files. JPEG via libjpeg-turbo, PNG via
// libpng, RAW as is, EXR via OpenEXR (half-float RGB, tone-mapped to 8 bits
// only for the statistics), H.264 via libavcodec through a session's
// FrameDecoder (h264_decoder.h).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "haarcast/proto/haarcast.pb.h"

namespace haarcast::client {

struct Rgba8Image {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<std::uint8_t> pixels;  // width·height·4, row 0 at the top
};

// Throws std::runtime_error naming the encoding and what failed (a truncated
// JPEG, a PNG of the wrong size, a RAW payload of the wrong length, …).
// `width`/`height` are what the Frame message claims; a decoded size that
// differs from them is an error too. H.264 frames depend on the frames
// before them: they go through a session's FrameDecoder, and here they are
// an error saying so.
Rgba8Image decodeFrame(v1::Encoding encoding, std::span<const std::uint8_t> data, std::uint32_t width,
                       std::uint32_t height);

class H264Decoder;

// The frames of one session, in order: H.264 through the session's own
// decoder (it keeps the reference pictures between frames, so every H.264
// frame must pass through it, also those not inspected), every other
// encoding through decodeFrame.
class FrameDecoder {
 public:
  FrameDecoder();
  ~FrameDecoder();
  FrameDecoder(const FrameDecoder&) = delete;
  FrameDecoder& operator=(const FrameDecoder&) = delete;

  Rgba8Image decode(v1::Encoding encoding, std::span<const std::uint8_t> data, std::uint32_t width,
                    std::uint32_t height);

 private:
  std::unique_ptr<H264Decoder> h264_;  // made at the first H.264 frame
};

struct PixelStats {
  double meanLuma = 0.0;    // Rec. 709 luma of the 8-bit sRGB values, 0..255
  double stddevLuma = 0.0;  // over all pixels
  double clippedFraction = 0.0;  // of the pixels with a channel at 255 (blown out)
};
PixelStats pixelStats(const Rgba8Image& image);

// A frame is blank when its luma barely varies: a solid clear colour, an
// all-black failed render. A frame that shows any object over the sky varies
// by tens of levels. The threshold is one 8-bit level of standard deviation.
inline constexpr double kBlankStddevLuma = 1.0;
inline bool isBlank(const PixelStats& s) { return s.stddevLuma < kBlankStddevLuma; }

// netpbm PAM (P7, RGB_ALPHA) bytes of an RGBA8 image: how raw frames are
// written to disk.
std::vector<std::uint8_t> encodePam(const Rgba8Image& image);

// PNG (8-bit RGBA) bytes of an RGBA8 image: how decoded H.264 frames are
// written under --out, since one access unit alone is no viewable file.
std::vector<std::uint8_t> encodePng(const Rgba8Image& image);

}  // namespace haarcast::client
