// The triple product in the Haar basis (triple_product.h): the sparse
// operands prepared into the walk's order, the walk itself, the per-call form
// that prepares both operands on every call, the brute-force reference, and
// the barycentric merge of per-vertex visibility.
#include <algorithm>
#include <stdexcept>
#include <string>

#include "haarcast/core/shared_layout.h"
#include "haarcast/core/triple_product.h"

namespace haarcast {
namespace {

using Details = std::array<double, 3>;

// S_child = (S_parent ± h ± v ± d) / 2: one synthesis step, with the signs
// of child `quadrant` (shared_layout.h haarChildSign, as the shader).
double childScaling(double parent, const Details& details, shared::uint quadrant) {
  const shared::vec3 sign = shared::haarChildSign(quadrant);
  return 0.5 * (parent + sign.x * details[0] + sign.y * details[1] + sign.z * details[2]);
}

// Sort word of one detail coefficient: key, then band, then its position in
// the input list (so that the last of duplicate indices comes last).
constexpr int kListBits = 2 * kMaxLevel;  // an index of a level-kMaxLevel map
constexpr int kBandShift = kListBits;
constexpr int kKeyShift = kListBits + 2;
static_assert(kKeyShift + 2 * kMaxLevel + 4 <= 64, "sort word overflows");
static_assert(kMaxLevel <= static_cast<int>(shared::kMaxPreorderLevel), "preorder keys overflow 32 bits");

}  // namespace

void PreparedSparseHaar::assign(const SparseHaar& x, const char* what) {
  if (x.level < 0 || x.level > kMaxLevel) {
    throw std::invalid_argument(std::string("tripleProduct: ") + what + " level " + std::to_string(x.level) +
                                " is outside [0, " + std::to_string(kMaxLevel) + "]");
  }
  if (x.index.size() != x.value.size()) {
    throw std::invalid_argument(std::string("tripleProduct: ") + what + " has " + std::to_string(x.index.size()) +
                                " indices but " + std::to_string(x.value.size()) + " values");
  }
  const int n = x.level;
  const std::uint64_t count = std::uint64_t{1} << (2 * n);
  if (x.index.size() > (std::uint64_t{1} << kListBits)) {
    throw std::invalid_argument(std::string("tripleProduct: ") + what + " has " + std::to_string(x.index.size()) +
                                " entries, more than a level-" + std::to_string(kMaxLevel) + " map has coefficients");
  }
  level_ = n;
  scaling_ = 0.0;
  order_.clear();
  for (std::size_t k = 0; k < x.index.size(); ++k) {
    const std::uint32_t index = x.index[k];
    if (index >= count) {
      throw std::invalid_argument(std::string("tripleProduct: ") + what + " index " + std::to_string(index) +
                                  " is outside a level-" + std::to_string(n) + " map");
    }
    if (index == 0) {
      scaling_ = x.value[k];
      continue;
    }
    // The walk's order, shared with triple_product.comp (shared_layout.h).
    const shared::HaarDetailPosition p = shared::haarDetailPosition(static_cast<shared::uint>(n), index);
    const std::uint64_t key = shared::haarPreorderKey(static_cast<shared::uint>(n - 1), p.level, p.i, p.j);
    order_.push_back((key << kKeyShift) | (std::uint64_t{p.band} << kBandShift) | k);
  }
  std::sort(order_.begin(), order_.end());

  blocks_.clear();
  constexpr std::uint64_t kListMask = (std::uint64_t{1} << kListBits) - 1;
  for (const std::uint64_t word : order_) {
    const std::uint64_t key = word >> kKeyShift;
    const auto band = static_cast<std::size_t>((word >> kBandShift) & 3u);
    const auto k = static_cast<std::size_t>(word & kListMask);
    if (blocks_.empty() || blocks_.back().key != key) {
      const shared::HaarDetailPosition p = shared::haarDetailPosition(static_cast<shared::uint>(n), x.index[k]);
      blocks_.push_back({key, static_cast<int>(p.level), static_cast<int>(p.i), static_cast<int>(p.j), {}});
    }
    blocks_.back().details[band] = x.value[k];
  }
}

double tripleProduct(const PreparedLight& light, const HaarMap& brdf, const PreparedVisibility& visibility) {
  const int n = brdf.level();
  if (light.level() != n || visibility.level() != n) {
    throw std::invalid_argument("tripleProduct: light level " + std::to_string(light.level()) + ", visibility level " +
                                std::to_string(visibility.level()) + ", brdf level " + std::to_string(n));
  }
  const std::span<const float> b = brdf.coefficients();
  const int m = mapSize(n);
  auto brdfDetails = [&](int l, int i, int j) -> Details {
    return {b[HaarMap::detailIndexOf(m, Band::Horizontal, l, i, j)], b[HaarMap::detailIndexOf(m, Band::Vertical, l, i, j)],
            b[HaarMap::detailIndexOf(m, Band::Diagonal, l, i, j)]};
  };

  // Term 1 of triple_product.h: all three scaling, C = 1/M.
  const double a0 = light.scaling(), b0 = brdf.scaling(), c0 = visibility.scaling();
  double sum = a0 * b0 * c0 / m;

  // The current root-to-block path, one entry per detail level: block
  // coordinates, the scaling values S_a, S_b, S_c of that block (S_c built
  // from the visibility's coarser coefficients, term 3 of triple_product.h),
  // and the light's and visibility's details there (zero for a block not
  // visited).
  std::array<int, kMaxLevel> pathI{}, pathJ{};
  std::array<double, kMaxLevel> sA{}, sB{}, sC{};
  std::array<Details, kMaxLevel> detA{}, detC{};
  int depth = 0;
  if (n > 0) {
    sA[0] = a0;
    sB[0] = b0;
    sC[0] = c0;
    depth = 1;
  }

  // Merge the two block lists, both in pre-order: O((k_L + k_V) log N).
  const std::span<const PreparedSparseHaar::Block> la = light.blocks(), lc = visibility.blocks();
  std::size_t ia = 0, ic = 0;
  while (ia < la.size() || ic < lc.size()) {
    const bool takeA = ic == lc.size() || (ia < la.size() && la[ia].key <= lc[ic].key);
    const bool takeC = ia == la.size() || (ic < lc.size() && lc[ic].key <= la[ia].key);
    const PreparedSparseHaar::Block& block = takeA ? la[ia] : lc[ic];
    const int l = block.level;

    // Deepest level shared with the current path; the root always is.
    int common = std::min(depth - 1, l);
    while (pathI[static_cast<std::size_t>(common)] != block.i >> (l - common) ||
           pathJ[static_cast<std::size_t>(common)] != block.j >> (l - common)) {
      --common;
    }
    // Descend to the block; blocks strictly between hold no light or
    // visibility detail (pre-order would have visited them).
    for (int d = common + 1; d <= l; ++d) {
      const auto parent = static_cast<std::size_t>(d - 1);
      const auto child = static_cast<std::size_t>(d);
      const int ci = block.i >> (l - d);
      const int cj = block.j >> (l - d);
      const shared::uint quadrant = shared::haarChildQuadrant(static_cast<shared::uint>(ci), static_cast<shared::uint>(cj));
      sA[child] = childScaling(sA[parent], detA[parent], quadrant);
      sB[child] = childScaling(sB[parent], brdfDetails(d - 1, pathI[parent], pathJ[parent]), quadrant);
      sC[child] = childScaling(sC[parent], detC[parent], quadrant);
      pathI[child] = ci;
      pathJ[child] = cj;
      detA[child] = {};
      detC[child] = {};
    }
    depth = l + 1;

    const auto at = static_cast<std::size_t>(l);
    if (takeA) detA[at] = la[ia++].details;
    if (takeC) detC[at] = lc[ic++].details;

    // Terms 2 and 3 of triple_product.h for this block, C = ±1/s.
    const Details& a = detA[at];
    const Details& c = detC[at];
    const Details bd = brdfDetails(l, block.i, block.j);
    double sameType = 0.0;
    for (std::size_t t = 0; t < 3; ++t) sameType += a[t] * bd[t] * sC[at] + a[t] * c[t] * sB[at] + bd[t] * c[t] * sA[at];
    const double allTypes = a[0] * (bd[1] * c[2] + bd[2] * c[1]) + a[1] * (bd[0] * c[2] + bd[2] * c[0]) +
                            a[2] * (bd[0] * c[1] + bd[1] * c[0]);
    sum += (sameType + allTypes) / mapSize(n - l);
  }
  return sum;
}

double tripleProduct(const SparseHaar& light, const HaarMap& brdf, const SparseHaar& visibility) {
  const PreparedLight preparedLight(light, "light");
  PreparedVisibility preparedVisibility;
  preparedVisibility.assign(visibility, "visibility");
  return tripleProduct(preparedLight, brdf, preparedVisibility);
}

double tripleProductBruteForce(const HaarMap& light, const HaarMap& brdf, const HaarMap& visibility) {
  if (light.level() != brdf.level() || visibility.level() != brdf.level()) {
    throw std::invalid_argument("tripleProductBruteForce: levels differ (light " + std::to_string(light.level()) +
                                ", brdf " + std::to_string(brdf.level()) + ", visibility " +
                                std::to_string(visibility.level()) + ")");
  }
  const SphereMap l = inverseHaar(light);
  const SphereMap b = inverseHaar(brdf);
  const SphereMap v = inverseHaar(visibility);
  double sum = 0.0;
  for (std::size_t p = 0; p < l.pixelCount(); ++p) {
    sum += static_cast<double>(l.values()[p]) * b.values()[p] * v.values()[p];
  }
  return sum;
}

double tripleProduct(const PreparedLight& light, const HaarMap& brdf, const SparseHaar& visibility,
                     TripleProductScratch& scratch) {
  scratch.visibility.assign(visibility, "visibility");
  return tripleProduct(light, brdf, scratch.visibility);
}

void mergeVisibility(const std::array<const SparseHaar*, 3>& vertices, const std::array<double, 3>& weights,
                     SparseHaar& out) {
  for (std::size_t v = 0; v < 3; ++v) {
    if (!vertices[v]) throw std::invalid_argument("mergeVisibility: vertex " + std::to_string(v) + " list is null");
    if (vertices[v]->level != vertices[0]->level) {
      throw std::invalid_argument("mergeVisibility: vertex " + std::to_string(v) + " has level " +
                                  std::to_string(vertices[v]->level) + ", vertex 0 level " +
                                  std::to_string(vertices[0]->level));
    }
    if (vertices[v]->index.size() != vertices[v]->value.size()) {
      throw std::invalid_argument("mergeVisibility: vertex " + std::to_string(v) + " has " +
                                  std::to_string(vertices[v]->index.size()) + " indices but " +
                                  std::to_string(vertices[v]->value.size()) + " values");
    }
  }
  out.level = vertices[0]->level;
  out.index.clear();
  out.value.clear();
  // A three-way merge of lists sorted by index; a list of weight 0 is empty.
  std::array<std::size_t, 3> next{}, end{};
  for (std::size_t v = 0; v < 3; ++v) end[v] = weights[v] != 0.0 ? vertices[v]->size() : 0;
  constexpr std::uint64_t kDone = std::uint64_t{1} << 32;
  auto head = [&](std::size_t v) -> std::uint64_t { return next[v] < end[v] ? vertices[v]->index[next[v]] : kDone; };
  for (;;) {
    const std::uint64_t index = std::min({head(0), head(1), head(2)});
    if (index == kDone) break;
    double value = 0.0;
    for (std::size_t v = 0; v < 3; ++v) {
      if (head(v) != index) continue;
      value += weights[v] * static_cast<double>(vertices[v]->value[next[v]]);
      ++next[v];
      if (next[v] < end[v] && vertices[v]->index[next[v]] <= index) {
        throw std::invalid_argument("mergeVisibility: vertex " + std::to_string(v) +
                                    " indices are not strictly increasing at position " + std::to_string(next[v]));
      }
    }
    out.index.push_back(static_cast<std::uint32_t>(index));
    out.value.push_back(static_cast<float>(value));
  }
}

}  // namespace haarcast
