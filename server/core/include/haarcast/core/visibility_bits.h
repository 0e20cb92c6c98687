// Visibility at map resolution, one bit per direction: what `fused` reads in
// place of the Haar methods' top-k coefficient lists (DESIGN.md "Per-pixel
// methods": fused works in the pixel basis, so it needs no truncation).
//
// Bit i of a point's map (i = row·M + col, the pixel order of SphereMap) is 1
// when the ray from the point toward pixel i's centre escapes. A level-6 map
// is 4,096 bits = 512 bytes a point; the bunny's 35k vertices hold 18 MB.
// Across a triangle V(ω) = Σ_v b_v·bit_v(ω), the barycentric blend of its
// three vertices: linear in V, as the triple product is.
//
// Words are 32 bits (the GPU's uint), direction i in word i / 32 at bit
// i % 32; a level-2 map (16 directions) fills half of one word.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "haarcast/core/sphere_map.h"

namespace haarcast {

class VisibilityBits {
 public:
  VisibilityBits() = default;
  // Every bit 0 (everything occluded) for `points` points at `level`.
  VisibilityBits(int level, std::size_t points);

  int level() const { return level_; }
  std::size_t pointCount() const { return points_; }
  std::size_t directions() const { return directions_; }
  std::size_t wordsPerPoint() const { return wordsPerPoint_; }
  std::size_t storedBytes() const { return words_.size() * sizeof(std::uint32_t); }

  std::span<const std::uint32_t> words() const { return words_; }
  std::span<const std::uint32_t> point(std::size_t p) const;
  std::span<std::uint32_t> point(std::size_t p);
  bool visible(std::size_t p, std::size_t direction) const;

  // Point p's map as 0/1 pixels (for the Haar methods and for tests).
  SphereMap map(std::size_t p) const;

  // Whole words at once (the cache's payload); throws std::invalid_argument
  // unless `words` has pointCount()·wordsPerPoint() entries with no bit set
  // past directions() in any point's last word.
  void assign(std::span<const std::uint32_t> words);

 private:
  int level_ = 0;
  std::size_t points_ = 0;
  std::size_t directions_ = 0;
  std::size_t wordsPerPoint_ = 0;
  std::vector<std::uint32_t> words_;
};

// Words a level needs per point: ⌈4^level / 32⌉.
std::size_t visibilityWordsPerPoint(int level);

// V(ω) at every direction of the map for one shading point: Σ_v weight_v ·
// bit_v(ω) over up to three points' words, into `out` (4^level floats).
struct WeightedBits {
  const std::uint32_t* words = nullptr;
  float weight = 0.0f;
  // The point's cell masks (fused_cells.h CellVisibility) where they were
  // built, for `fused`'s sum by cells; null: formed from `words` per pixel.
  const std::uint32_t* cells = nullptr;
};
void blendVisibility(std::span<const WeightedBits> points, int level, std::span<float> out);

}  // namespace haarcast
