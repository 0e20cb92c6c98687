// VisibilityBits (visibility_bits.h): storage, the 0/1 map of a point, and
// the per-pixel barycentric blend.
#include "haarcast/core/visibility_bits.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "haarcast/core/check.h"
#include "haarcast/core/shared_layout.h"

namespace haarcast {

std::size_t visibilityWordsPerPoint(int level) {
  checkLevel(level, "visibility bits");
  return shared::visibilityWords(static_cast<shared::uint>(level));
}

VisibilityBits::VisibilityBits(int level, std::size_t points)
    : level_(level),
      points_(points),
      directions_(static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level))),
      wordsPerPoint_(visibilityWordsPerPoint(level)),
      words_(points * wordsPerPoint_, 0u) {}

std::span<const std::uint32_t> VisibilityBits::point(std::size_t p) const {
  HC_CHECK_LT(p, points_);
  return {words_.data() + p * wordsPerPoint_, wordsPerPoint_};
}

std::span<std::uint32_t> VisibilityBits::point(std::size_t p) {
  HC_CHECK_LT(p, points_);
  return {words_.data() + p * wordsPerPoint_, wordsPerPoint_};
}

bool VisibilityBits::visible(std::size_t p, std::size_t direction) const {
  HC_CHECK_LT(direction, directions_);
  return ((point(p)[direction / 32] >> (direction % 32)) & 1u) != 0;
}

SphereMap VisibilityBits::map(std::size_t p) const {
  SphereMap out(level_);
  const std::span<const std::uint32_t> w = point(p);
  const int m = mapSize(level_);
  for (std::size_t i = 0; i < directions_; ++i) {
    out.at(static_cast<int>(i) / m, static_cast<int>(i) % m) = ((w[i / 32] >> (i % 32)) & 1u) ? 1.0f : 0.0f;
  }
  return out;
}

void VisibilityBits::assign(std::span<const std::uint32_t> words) {
  if (words.size() != words_.size()) {
    throw std::invalid_argument("visibility bits: " + std::to_string(words.size()) + " words for " +
                                std::to_string(points_) + " points of " + std::to_string(wordsPerPoint_));
  }
  const std::size_t used = directions_ % 32;
  if (used != 0) {
    const std::uint32_t spare = ~((1u << used) - 1u);
    for (std::size_t p = 0; p < points_; ++p) {
      if (words[p * wordsPerPoint_ + wordsPerPoint_ - 1] & spare) {
        throw std::invalid_argument("visibility bits: point " + std::to_string(p) + " sets bits past direction " +
                                    std::to_string(directions_));
      }
    }
  }
  std::copy(words.begin(), words.end(), words_.begin());
}

void blendVisibility(std::span<const WeightedBits> points, int level, std::span<float> out) {
  const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  HC_CHECK_EQ(out.size(), n);
  std::fill(out.begin(), out.end(), 0.0f);
  for (const WeightedBits& p : points) {
    if (p.weight == 0.0f) continue;
    // Word by word: a zero word (a fully occluded run of 32 directions)
    // costs one test.
    for (std::size_t w = 0; w * 32 < n; ++w) {
      std::uint32_t bits = p.words[w];
      float* dst = out.data() + w * 32;
      while (bits) {
        const int b = __builtin_ctz(bits);
        dst[b] += p.weight;
        bits &= bits - 1u;
      }
    }
  }
}

}  // namespace haarcast
