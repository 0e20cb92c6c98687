// The CLI client's H.264 decoder (ENCODING_H264): libavcodec's h264 decoder,
// one Annex-B access unit in, one RGBA8 picture out, row 0 at the top, so
// --check-not-blank and --out work on H.264 streams as on JPEG frames.
//
// Colour follows the stream's VUI (the server writes BT.709, limited range:
// server/net/include/haarcast/net/h264_encoder.h); a stream that states none
// is read as BT.601 limited range, as libswscale and browsers do.
//
// Stateful: a frame refers to the frames before it, so one decoder serves
// one session and sees every frame in order. A stream must start at a
// keyframe (SPS, PPS, IDR); an access unit that yields no picture is an
// error naming the frame, never a blank image.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "haarcast/wire/image.h"

namespace haarcast::client {

class H264Decoder {
 public:
  H264Decoder();  // throws std::runtime_error when libavcodec has no h264 decoder
  ~H264Decoder();
  H264Decoder(const H264Decoder&) = delete;
  H264Decoder& operator=(const H264Decoder&) = delete;

  // Decodes one access unit. `width`/`height` are what the Frame message
  // claims; a picture of another size is an error. Throws std::runtime_error
  // naming the libavcodec call and its AVERROR text.
  wire::Rgba8Image decode(std::span<const std::uint8_t> annexB, std::uint32_t width, std::uint32_t height);

  std::uint64_t framesDecoded() const { return frames_; }

 private:
  struct Codec;
  std::unique_ptr<Codec> codec_;
  std::uint64_t frames_ = 0;
};

}  // namespace haarcast::client
