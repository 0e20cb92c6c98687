// ENCODING_EXR: OpenEXR in memory, linear half RGB (ZIP), the renderer's
// numbers rounded to half, for exact checks. Errors as in frame_codec.h:
// std::runtime_error starting "exr: ", and bytes that are not EXR never
// crash the decoder.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "haarcast/wire/image.h"

namespace haarcast::wire {

// rgb: width·height·3 linear floats, row 0 at the top.
std::string encodeExr(std::span<const float> rgb, std::uint32_t width, std::uint32_t height);

// R, G, B as float (from half); A is ignored. `expected`: as in frame_codec.h.
LinearImage decodeExr(std::string_view bytes, std::optional<ImageSize> expected = std::nullopt);

}  // namespace haarcast::wire
