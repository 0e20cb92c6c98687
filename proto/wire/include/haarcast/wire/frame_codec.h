// The 8-bit frame codecs: what a Frame's `data` holds for
//
//   ENCODING_JPEG       libjpeg-turbo, from the tonemapped RGBA8 (sRGB), 4:2:0, quality 1..100
//   ENCODING_PNG        libpng (simplified API, in memory), 8-bit sRGB RGBA, lossless
//   ENCODING_RAW_RGBA8  the RGBA8 bytes as they are: width·height·4, row 0 at the top
//
// EXR (linear floats) is exr_codec.h; H.264 is a stream, not a picture per
// frame: the server's session encoder (net/h264_encoder.h) and the CLI
// client's session decoder (client/h264_decoder.h). decodeFrame
// (frame_decode.h) picks the decoder by a Frame's encoding.
//
// Encoded bytes are std::string, the type of a Frame's `data`. Every
// function throws std::runtime_error naming the codec ("jpeg: …") and what
// was wrong; a decoder given bytes that are not its format never crashes.
// A decoder given `expected` (the size the Frame message claims) refuses a
// picture of another size before it allocates its pixels.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "haarcast/wire/image.h"

namespace haarcast::wire {

// rgba8: width·height·4 bytes, row 0 at the top. jpegQuality is clamped to 1..100.
std::string encodeJpeg(std::span<const std::uint8_t> rgba8, std::uint32_t width, std::uint32_t height,
                       int jpegQuality);
std::string encodePng(std::span<const std::uint8_t> rgba8, std::uint32_t width, std::uint32_t height);
std::string encodeRaw(std::span<const std::uint8_t> rgba8, std::uint32_t width, std::uint32_t height);

Rgba8Image decodeJpeg(std::string_view bytes, std::optional<ImageSize> expected = std::nullopt);
Rgba8Image decodePng(std::string_view bytes, std::optional<ImageSize> expected = std::nullopt);
// RAW has no header: the size is the Frame's, and the length must match it.
Rgba8Image decodeRaw(std::string_view bytes, ImageSize size);

}  // namespace haarcast::wire
