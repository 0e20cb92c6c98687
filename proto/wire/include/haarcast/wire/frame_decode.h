// A Frame's payload back to 8-bit pixels, whatever its encoding: for the
// CLI client's not-blank and clipping checks, for writing raw frames as
// viewable files, and for the tests of the server's frames.
#pragma once

#include <cstdint>
#include <string_view>

#include "haarcast/proto/haarcast.pb.h"
#include "haarcast/wire/image.h"

namespace haarcast::wire {

// `width`/`height` are what the Frame message claims; a payload that decodes
// to another size is an error, as are a payload not of its encoding (a
// truncated JPEG, a RAW payload of the wrong length, …) and an unknown
// encoding. EXR's linear values are shown as sRGB, clamped to [0, 1], with
// no exposure or tone curve. H.264 frames depend on the ones before them:
// here they are an error saying so (the CLI client's FrameDecoder decodes
// them in order). Throws std::runtime_error naming the codec.
Rgba8Image decodeFrame(v1::Encoding encoding, std::string_view data, std::uint32_t width, std::uint32_t height);

// The 8-bit sRGB code of a linear value (IEC 61966-2-1), clamped to [0, 1];
// NaN shows as 0.
std::uint8_t linearToSrgb8(float linear);

}  // namespace haarcast::wire
