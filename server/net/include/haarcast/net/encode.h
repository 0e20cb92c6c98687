// Frame encoders (and their decoders, for tests and clients): what a Frame's
// `data` holds for each wire Encoding.
//
//   JPEG      libjpeg-turbo, from the tonemapped RGBA8 (sRGB), 4:2:0, quality 1..100
//   PNG       libpng, 8-bit sRGB RGBA, lossless
//   RAW       the RGBA8 bytes as they are: width·height·4, row 0 at the top
//   EXR       OpenEXR in memory, linear half RGB (ZIP): the renderer's numbers,
//             rounded to half, for exact checks
//   H264      one Annex-B access unit per frame: stateful (each frame depends
//             on the ones before), so a session's own H264Encoder
//             (h264_encoder.h) encodes it, never encodeFrame
//
// All of them throw std::runtime_error naming the codec and what was wrong;
// a decoder given bytes that are not its format never crashes.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "haarcast/io/image.h"

namespace haarcast::net {

enum class FrameEncoding { Jpeg, Png, RawRgba8, Exr, H264 };

std::string_view encodingName(FrameEncoding encoding);  // "jpeg", "png", "raw", "exr", "h264"

// rgba8: width·height·4 bytes. jpegQuality is clamped to 1..100.
std::string encodeJpeg(const std::vector<std::uint8_t>& rgba8, int width, int height, int jpegQuality);
std::string encodePng(const std::vector<std::uint8_t>& rgba8, int width, int height);
std::string encodeRaw(const std::vector<std::uint8_t>& rgba8, int width, int height);
std::string encodeExr(const io::RgbImage& linear);

// One entry point: the RGBA8 image (width × height) for the 8-bit
// encodings, the linear one for EXR (a frame rendered for an 8-bit encoding
// may carry no linear image: FrameRequest::linearImage).
std::string encodeFrame(FrameEncoding encoding, const std::vector<std::uint8_t>& rgba8, int width, int height,
                        const io::RgbImage& linear, int jpegQuality);

struct Rgba8Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;  // 4 bytes per pixel, row 0 at the top
};

Rgba8Image decodeJpeg(std::string_view bytes);
Rgba8Image decodePng(std::string_view bytes);
io::RgbImage decodeExr(std::string_view bytes);  // R, G, B as float (from half)

}  // namespace haarcast::net
