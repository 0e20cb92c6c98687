// The pictures a Frame's `data` carries, as plain types: what the codecs of
// frame_codec.h and exr_codec.h take and give, shared by the server, the CLI
// client and the tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace haarcast::wire {

// A decoder's sanity bounds, checked before it allocates: a header that
// claims more is corrupt or hostile, not a frame. (A frame's own limits are
// far smaller: render/render_options.h and Welcome.limits.) The same
// numbers as io::kMaxImageDimension and io::kMaxImagePixels for files.
inline constexpr std::uint32_t kMaxImageSide = 32768;
inline constexpr std::size_t kMaxImagePixels = std::size_t{1} << 28;

struct ImageSize {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  friend bool operator==(const ImageSize&, const ImageSize&) = default;
};

// 8-bit sRGB RGBA, what JPEG, PNG, RAW_RGBA8 and a decoded H.264 picture hold.
struct Rgba8Image {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<std::uint8_t> pixels;  // width·height·4, row 0 at the top
};

// Linear RGB floats, what EXR holds: the renderer's radiance.
struct LinearImage {
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  std::vector<float> rgb;  // width·height·3, row 0 at the top
};

}  // namespace haarcast::wire
