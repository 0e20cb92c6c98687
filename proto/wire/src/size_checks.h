// The checks every codec of the wire library makes on a picture's size, with
// the codec's name in front of the message ("png: …").
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include "haarcast/wire/image.h"

namespace haarcast::wire::detail {

inline std::string sizeText(std::int64_t width, std::int64_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

inline bool sizeIsSane(std::int64_t width, std::int64_t height) {
  return width > 0 && height > 0 && width <= std::int64_t{kMaxImageSide} && height <= std::int64_t{kMaxImageSide} &&
         static_cast<std::size_t>(width) * static_cast<std::size_t>(height) <= kMaxImagePixels;
}

// A decoder's header: a sane size, and the one the Frame claims when given;
// checked before any pixel is allocated.
inline ImageSize checkDecodedSize(const char* codec, std::int64_t width, std::int64_t height,
                                  const std::optional<ImageSize>& expected) {
  if (!sizeIsSane(width, height)) throw std::runtime_error(std::string(codec) + ": absurd size " + sizeText(width, height));
  const ImageSize size{static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height)};
  if (expected && size != *expected) {
    throw std::runtime_error(std::string(codec) + ": the frame decodes to " + sizeText(width, height) +
                             " but the Frame message says " + sizeText(expected->width, expected->height));
  }
  return size;
}

}  // namespace haarcast::wire::detail
