#include "haarcast/gpu/passes.h"

#include "haarcast/core/sphere_map.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>
#include <glm/trigonometric.hpp>

#include "haarcast/render/shading.h"

namespace haarcast::gpu {

CameraBasis cameraBasis(const render::Camera& camera) {
  // The basis of render::CameraRays, computed the same way in double.
  CameraBasis b;
  b.forward = glm::normalize(camera.target - camera.eye);
  b.right = glm::normalize(glm::cross(b.forward, camera.up));
  b.up = glm::cross(b.right, b.forward);
  b.tanHalf = std::tan(glm::radians(camera.fovYDegrees) * 0.5);
  return b;
}

FrameParams makeFrameParams(const render::Camera& camera, int width, int height, const glm::dmat3& lightRotation,
                            double exposureStops, bool background, int backgroundLevel) {
  const CameraBasis basis = cameraBasis(camera);
  FrameParams f{};
  f.forward = glm::vec4(glm::vec3(basis.forward), 0.0f);
  f.right = glm::vec4(glm::vec3(basis.right), 0.0f);
  f.up = glm::vec4(glm::vec3(basis.up), 0.0f);
  const glm::dmat3 lt = glm::transpose(lightRotation);
  for (int c = 0; c < 3; ++c) f.lightRotT[c] = glm::vec4(glm::vec3(lt[c]), 0.0f);
  f.tanHalf = static_cast<float>(render::verticalTanHalf(camera, width, height));
  f.aspect = static_cast<float>(static_cast<double>(width) / height);
  f.gain = static_cast<float>(std::exp2(exposureStops));
  f.background = background ? 1u : 0u;
  f.width = static_cast<std::uint32_t>(width);
  f.height = static_cast<std::uint32_t>(height);
  f.backgroundLevel = static_cast<std::uint32_t>(backgroundLevel);
  return f;
}

void setFusedSkip(ObjectInfo& info, int level, int lastNonZeroRow) {
  // As fusedShade: beyond the last non-zero row + 1 every lookup reads zeros;
  // one more row absorbs the rounding of θ'. The taps of the directions kept
  // reach rows up to cutRow (r0 ≤ cutRow − 1, r1 = r0 + 1).
  const int m = mapSize(level), cutRow = lastNonZeroRow + 2;
  info.skipBelowY = cutRow < m ? static_cast<float>(std::cos(cutRow * kPi / m)) : -2.0f;
  info.blendRows = static_cast<std::uint32_t>(std::min(m, cutRow + 1));
}

std::vector<glm::vec4> pixelCentreDirections(int level) {
  const int m = mapSize(level);
  std::vector<glm::vec4> out;
  out.reserve(static_cast<std::size_t>(m) * static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) out.emplace_back(glm::vec3(sphericalToDirection(rowTheta(level, i), colPhi(level, j))), 0.0f);
  }
  return out;
}

std::vector<std::uint32_t> packVisibilityEntries(std::span<const SparseHaar> lists, int level) {
  const std::size_t count = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  std::vector<std::uint32_t> out(2 * lists.size());
  for (std::size_t n = 0; n < lists.size(); ++n) {
    const SparseHaar& list = lists[n];
    if (list.level != level || list.index.size() != list.value.size()) {
      throw std::invalid_argument("packVisibilityEntries: list " + std::to_string(n) + " has level " +
                                  std::to_string(list.level) + " (expected " + std::to_string(level) + ") or " +
                                  "unequal index and value counts");
    }
    out[2 * n] = static_cast<std::uint32_t>(out.size() / 2);
    out[2 * n + 1] = static_cast<std::uint32_t>(list.size());
    for (std::size_t k = 0; k < list.size(); ++k) {
      if (list.index[k] >= count) {
        throw std::invalid_argument("packVisibilityEntries: list " + std::to_string(n) + " index " +
                                    std::to_string(list.index[k]) + " is outside a level-" + std::to_string(level) + " map");
      }
      out.push_back(list.index[k]);
      out.push_back(std::bit_cast<std::uint32_t>(list.value[k]));
    }
  }
  return out;
}

std::uint32_t preorderKey(int mapLevel, int l, int i, int j) {
  // triple_product.cpp's key, which fits 32 bits for levels ≤ 14.
  const int finest = mapLevel - 1;
  const int shift = finest - l;
  const auto row = static_cast<std::uint32_t>(i) << shift;
  const auto col = static_cast<std::uint32_t>(j) << shift;
  std::uint32_t morton = 0;
  for (int b = 0; b <= finest; ++b) {
    morton |= ((row >> b) & 1u) << (2 * b + 1);
    morton |= ((col >> b) & 1u) << (2 * b);
  }
  return (morton << 4) | static_cast<std::uint32_t>(l);
}

namespace {
struct Block {
  std::uint32_t key;
  float hvd[3];
};

std::vector<Block> blocksOf(const SparseHaar& list) {
  std::vector<Block> blocks;
  for (std::size_t k = 0; k < list.size(); ++k) {
    const CoefficientPosition p = coefficientPosition(list.level, list.index[k]);
    if (p.isScaling) continue;
    blocks.push_back({preorderKey(list.level, p.level, p.i, p.j), {0, 0, 0}});
    blocks.back().hvd[static_cast<int>(p.band)] = list.value[k];
  }
  std::stable_sort(blocks.begin(), blocks.end(), [](const Block& a, const Block& b) { return a.key < b.key; });
  // One entry per block: merge the bands of equal keys.
  std::vector<Block> merged;
  for (const Block& b : blocks) {
    if (!merged.empty() && merged.back().key == b.key) {
      for (int t = 0; t < 3; ++t) merged.back().hvd[t] += b.hvd[t];
    } else {
      merged.push_back(b);
    }
  }
  return merged;
}
}  // namespace

std::size_t blockCount(const SparseHaar& list) { return blocksOf(list).size(); }

std::vector<glm::uvec4> packSparseLists(std::span<const SparseHaar> lists, int level) {
  std::vector<glm::uvec4> out(lists.size());
  for (std::size_t n = 0; n < lists.size(); ++n) {
    const SparseHaar& list = lists[n];
    if (list.level != level) {
      throw std::invalid_argument("packSparseLists: list " + std::to_string(n) + " has level " +
                                  std::to_string(list.level) + ", expected " + std::to_string(level));
    }
    if (list.index.size() != list.value.size()) {
      throw std::invalid_argument("packSparseLists: list " + std::to_string(n) + " has " +
                                  std::to_string(list.index.size()) + " indices but " +
                                  std::to_string(list.value.size()) + " values");
    }
    const std::size_t count = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
    float scaling = 0.0f;
    for (std::size_t k = 0; k < list.size(); ++k) {
      if (list.index[k] >= count) {
        throw std::invalid_argument("packSparseLists: list " + std::to_string(n) + " index " +
                                    std::to_string(list.index[k]) + " is outside a level-" + std::to_string(level) +
                                    " map");
      }
      if (list.index[k] == 0) scaling = list.value[k];
    }
    const std::vector<Block> blocks = blocksOf(list);
    out[n] = glm::uvec4(static_cast<std::uint32_t>(out.size()), static_cast<std::uint32_t>(blocks.size()),
                        std::bit_cast<std::uint32_t>(scaling), 0u);
    for (const Block& b : blocks) {
      out.emplace_back(b.key, std::bit_cast<std::uint32_t>(b.hvd[0]), std::bit_cast<std::uint32_t>(b.hvd[1]),
                       std::bit_cast<std::uint32_t>(b.hvd[2]));
    }
  }
  return out;
}

}  // namespace haarcast::gpu
