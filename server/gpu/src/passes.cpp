#include "haarcast/gpu/passes.h"

#include "haarcast/core/check.h"
#include "haarcast/core/fused.h"
#include "haarcast/core/fused_cells.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/render/shading.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>

namespace haarcast::gpu {

FrameParams makeFrameParams(const render::Camera& camera, int width, int height, const glm::dmat3& lightRotation,
                            bool background, int backgroundLevel) {
  return makeFrameParams(render::cameraBasis(camera, width, height), width, height, lightRotation, background,
                         backgroundLevel);
}

FrameParams makeFrameParams(const render::CameraBasis& basis, int width, int height, const glm::dmat3& lightRotation,
                            bool background, int backgroundLevel) {
  FrameParams f{};
  f.forward = glm::vec4(glm::vec3(basis.forward), 0.0f);
  f.right = glm::vec4(glm::vec3(basis.right), 0.0f);
  f.up = glm::vec4(glm::vec3(basis.up), 0.0f);
  const glm::dmat3 lt = glm::transpose(lightRotation);
  for (int c = 0; c < 3; ++c) f.lightRotT[c] = glm::vec4(glm::vec3(lt[c]), 0.0f);
  f.tanHalf = static_cast<float>(basis.tanHalf);
  f.aspect = static_cast<float>(static_cast<double>(width) / height);
  f.background = background ? 1u : 0u;
  f.width = static_cast<std::uint32_t>(width);
  f.height = static_cast<std::uint32_t>(height);
  f.backgroundLevel = static_cast<std::uint32_t>(backgroundLevel);
  return f;
}

void setFusedSkip(ObjectInfo& info, int level, int lastNonZeroRow) {
  // As fusedShade: beyond the last non-zero row + 1 every lookup reads zeros;
  // one more row absorbs the rounding of θ'.
  const int m = mapSize(level), cutRow = lastNonZeroRow + 2;
  info.skipBelowY = cutRow < m ? static_cast<float>(std::cos(cutRow * kPi / m)) : -2.0f;
}

std::vector<BindingKind> fusedBindings() {
  std::vector<BindingKind> kinds(shared::kFusedBindings, BindingKind::Storage);
  for (const shared::uint b : {shared::kFusedSliceTexelsBinding, shared::kFusedLightTexelsBinding,
                               shared::kFusedVisibilityTexelsBinding, shared::kFusedDirectionTexelsBinding,
                               shared::kFusedLobeLightTexelsBinding, shared::kFusedPointSliceTexelsBinding,
                               shared::kFusedDetailTexelsBinding}) {
    kinds[b] = BindingKind::Texels;
  }
  return kinds;
}

std::vector<BindingKind> splitsumBindings() {
  std::vector<BindingKind> kinds(shared::kSplitsumBindings, BindingKind::Storage);
  kinds[shared::kSplitsumLobeLightTexelsBinding] = BindingKind::Texels;
  return kinds;
}

void fusedLightTexels(std::span<const float> planes, std::span<glm::vec4> out) {
  const std::size_t n = out.size();
  if (planes.size() != 3 * n) {
    throw std::invalid_argument("fusedLightTexels: " + std::to_string(planes.size()) + " plane floats for " +
                                std::to_string(n) + " texels");
  }
  for (std::size_t k = 0; k < n; ++k) out[k] = glm::vec4(planes[k], planes[n + k], planes[2 * n + k], 0.0f);
}

std::vector<glm::vec4> pixelCentreDirections(int level) {
  const int m = mapSize(level);
  std::vector<glm::vec4> out;
  out.reserve(static_cast<std::size_t>(m) * static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) {
    // w: the pixel's solid angle, as core fused's table holds it (float).
    const auto omega = static_cast<float>(pixelSolidAngle(level, i));
    for (int j = 0; j < m; ++j) out.emplace_back(glm::vec3(sphericalToDirection(rowTheta(level, i), colPhi(level, j))), omega);
  }
  return out;
}

DirectionTable pixelCentreDirections(std::span<const int> levels) {
  std::vector<int> sorted(levels.begin(), levels.end());
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  DirectionTable out;
  for (const int level : sorted) {
    checkFusedLevel(level);
    out.base[static_cast<std::size_t>(level)] = static_cast<std::uint32_t>(out.directions.size());
    const std::vector<glm::vec4> one = pixelCentreDirections(level);
    out.directions.insert(out.directions.end(), one.begin(), one.end());
    if (level < static_cast<int>(shared::kCellMinLevel)) continue;
    // The sum by cells' centres and Ω_C after them (shared::cellCentreTexel),
    // the CPU's floats.
    const CellDirections& cells = cellDirections(level);
    for (std::size_t q = 0; q + kCellPadding < cells.centreX.size(); ++q)
      out.directions.emplace_back(cells.centreX[q], cells.centreY[q], cells.centreZ[q], cells.cellSolidAngle[q]);
  }
  return out;
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
    blocks.push_back({shared::haarPreorderKey(static_cast<shared::uint>(list.level - 1), static_cast<shared::uint>(p.level),
                                              static_cast<shared::uint>(p.i), static_cast<shared::uint>(p.j)),
                      {0, 0, 0}});
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
