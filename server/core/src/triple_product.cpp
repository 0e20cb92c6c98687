#include "haarcast/core/triple_product.h"

#include <algorithm>
#include <array>
#include <string>

namespace haarcast {
namespace {

// (h, v, d) details of one block.
using Details = std::array<double, 3>;

// Signs of (h, v, d) in the synthesis of child quadrant 2·rowBit + colBit
// (haar.cpp, synthesisStep): top-left, top-right, bottom-left, bottom-right.
constexpr std::array<Details, 4> kChildSign{{{1, 1, 1}, {-1, 1, -1}, {1, -1, -1}, {-1, -1, 1}}};

// Scaling value of a child block from its parent's: one synthesis step,
// S_child = (S_parent ± h ± v ± d) / 2.
double childScaling(double parent, const Details& details, int quadrant) {
  const Details& sign = kChildSign[static_cast<std::size_t>(quadrant)];
  return 0.5 * (parent + sign[0] * details[0] + sign[1] * details[1] + sign[2] * details[2]);
}

Details denseDetails(const HaarMap& map, int l, int i, int j) {
  return {map.detail(Band::Horizontal, l, i, j), map.detail(Band::Vertical, l, i, j),
          map.detail(Band::Diagonal, l, i, j)};
}

// Position of block (l, i, j) in a pre-order walk of the block quadtree:
// the Morton code of its top-left finest block, ties (a block and its
// top-left descendants) broken coarser first. A block's descendants then
// follow it contiguously, so its ancestors are always visited before it.
std::uint64_t preorderKey(int finestLevel, int l, int i, int j) {
  const int shift = finestLevel - l;
  const auto row = static_cast<std::uint64_t>(i) << shift;
  const auto col = static_cast<std::uint64_t>(j) << shift;
  std::uint64_t morton = 0;
  for (int b = 0; b <= finestLevel; ++b) {
    morton |= ((row >> b) & 1u) << (2 * b + 1);
    morton |= ((col >> b) & 1u) << (2 * b);
  }
  return (morton << 4) | static_cast<std::uint64_t>(l);  // l ≤ kMaxLevel < 16
}

// A non-zero detail coefficient of the light or of the visibility.
struct DetailEntry {
  std::uint64_t key;
  CoefficientPosition position;
  bool isLight;
  double value;
};

void checkOperand(const SparseHaar& x, const char* name, const HaarMap& brdf) {
  if (x.level != brdf.level()) {
    throw std::invalid_argument(std::string("tripleProduct: ") + name + " level " + std::to_string(x.level) +
                                " differs from brdf level " + std::to_string(brdf.level()));
  }
  if (x.index.size() != x.value.size()) {
    throw std::invalid_argument(std::string("tripleProduct: ") + name + " has " + std::to_string(x.index.size()) +
                                " indices but " + std::to_string(x.value.size()) + " values");
  }
  for (const std::uint32_t index : x.index) {
    if (index >= brdf.coefficientCount()) {
      throw std::invalid_argument(std::string("tripleProduct: ") + name + " index " + std::to_string(index) +
                                  " is outside a level-" + std::to_string(x.level) + " map");
    }
  }
}

void checkLevels(const HaarMap& light, const HaarMap& brdf, const HaarMap& visibility) {
  if (light.level() != brdf.level() || visibility.level() != brdf.level()) {
    throw std::invalid_argument("tripleProductBruteForce: levels differ (light " + std::to_string(light.level()) +
                                ", brdf " + std::to_string(brdf.level()) + ", visibility " +
                                std::to_string(visibility.level()) + ")");
  }
}

}  // namespace

double tripleProduct(const SparseHaar& light, const HaarMap& brdf, const SparseHaar& visibility) {
  checkOperand(light, "light", brdf);
  checkOperand(visibility, "visibility", brdf);
  const int n = brdf.level();
  const int finest = n - 1;  // finest detail level

  // Term 1 of triple_product.h: all three scaling, C = 1/M.
  const double a0 = !light.index.empty() && light.index[0] == 0 ? light.value[0] : 0.0;
  const double b0 = brdf.scaling();
  const double c0 = !visibility.index.empty() && visibility.index[0] == 0 ? visibility.value[0] : 0.0;
  double sum = a0 * b0 * c0 / mapSize(n);

  // The blocks where the light or the visibility has a detail, in pre-order,
  // so that one root-to-block path, updated incrementally, gives every
  // block's scaling values: O((k_L + k_V) log N) after the sort.
  std::vector<DetailEntry> entries;
  entries.reserve(light.size() + visibility.size());
  auto collect = [&](const SparseHaar& x, bool isLight) {
    for (std::size_t k = 0; k < x.size(); ++k) {
      const CoefficientPosition p = coefficientPosition(n, x.index[k]);
      if (p.isScaling) continue;
      entries.push_back({preorderKey(finest, p.level, p.i, p.j), p, isLight, x.value[k]});
    }
  };
  collect(light, true);
  collect(visibility, false);
  std::sort(entries.begin(), entries.end(),
            [](const DetailEntry& x, const DetailEntry& y) { return x.key < y.key; });

  // The current root-to-block path, one entry per detail level: block
  // coordinates, the scaling values S_a, S_b, S_c of that block, and the
  // light's and visibility's details there (zero for a block not visited).
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

  for (std::size_t first = 0; first < entries.size();) {
    const CoefficientPosition& block = entries[first].position;
    const int l = block.level;

    // Deepest level shared with the current path; the root always is.
    int common = std::min(depth - 1, l);
    while (pathI[static_cast<std::size_t>(common)] != block.i >> (l - common) ||
           pathJ[static_cast<std::size_t>(common)] != block.j >> (l - common)) {
      --common;
    }
    // Descend to the block. Blocks strictly between `common` and `l` hold no
    // light or visibility detail: pre-order would have visited them already.
    for (int d = common + 1; d <= l; ++d) {
      const auto parent = static_cast<std::size_t>(d - 1);
      const auto child = static_cast<std::size_t>(d);
      const int ci = block.i >> (l - d);
      const int cj = block.j >> (l - d);
      const int quadrant = 2 * (ci & 1) + (cj & 1);
      const Details detB = denseDetails(brdf, d - 1, pathI[parent], pathJ[parent]);
      sA[child] = childScaling(sA[parent], detA[parent], quadrant);
      sB[child] = childScaling(sB[parent], detB, quadrant);
      sC[child] = childScaling(sC[parent], detC[parent], quadrant);
      pathI[child] = ci;
      pathJ[child] = cj;
      detA[child] = {};
      detC[child] = {};
    }
    depth = l + 1;

    // Gather this block's light and visibility details.
    const auto at = static_cast<std::size_t>(l);
    std::size_t last = first;
    for (; last < entries.size() && entries[last].key == entries[first].key; ++last) {
      Details& det = entries[last].isLight ? detA[at] : detC[at];
      det[static_cast<std::size_t>(entries[last].position.band)] = entries[last].value;
    }
    first = last;

    // Terms 2 and 3 of triple_product.h for this block, C = ±1/s.
    const Details& a = detA[at];
    const Details& c = detC[at];
    const Details b = denseDetails(brdf, l, block.i, block.j);
    double sameType = 0.0;
    for (std::size_t t = 0; t < 3; ++t) {
      sameType += a[t] * b[t] * sC[at] + a[t] * c[t] * sB[at] + b[t] * c[t] * sA[at];
    }
    const double allTypes = a[0] * (b[1] * c[2] + b[2] * c[1]) + a[1] * (b[0] * c[2] + b[2] * c[0]) +
                            a[2] * (b[0] * c[1] + b[1] * c[0]);
    sum += (sameType + allTypes) / mapSize(n - l);
  }
  return sum;
}

double tripleProductBruteForce(const HaarMap& light, const HaarMap& brdf, const HaarMap& visibility) {
  checkLevels(light, brdf, visibility);
  const SphereMap l = inverseHaar(light);
  const SphereMap b = inverseHaar(brdf);
  const SphereMap v = inverseHaar(visibility);
  double sum = 0.0;
  for (std::size_t p = 0; p < l.pixelCount(); ++p) {
    sum += static_cast<double>(l.values()[p]) * b.values()[p] * v.values()[p];
  }
  return sum;
}

}  // namespace haarcast
