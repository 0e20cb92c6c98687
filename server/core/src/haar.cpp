#include "haarcast/core/haar.h"

#include <algorithm>
#include <numeric>

namespace haarcast {

HaarMap::HaarMap(int level) : level_(level) {
  checkLevel(level, "HaarMap");
  coeffs_.assign(static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level)), 0.0f);
}

CoefficientPosition coefficientPosition(int mapLevel, std::size_t index) {
  CoefficientPosition p;
  if (index == 0) {
    p.isScaling = true;
    return p;
  }
  const shared::HaarDetailPosition d =
      shared::haarDetailPosition(static_cast<shared::uint>(mapLevel), static_cast<shared::uint>(index));
  p.band = static_cast<Band>(d.band);
  p.level = static_cast<int>(d.level);
  p.i = static_cast<int>(d.i);
  p.j = static_cast<int>(d.j);
  return p;
}

int supportSide(int mapLevel, std::size_t index) {
  const CoefficientPosition p = coefficientPosition(mapLevel, index);
  return p.isScaling ? mapSize(mapLevel) : mapSize(mapLevel - p.level);
}

// One analysis step on the top-left `n`×`n` block of a row-major array of
// row stride `stride`: writes s, h, v, d into the quadrants of that block.
static void analysisStep(std::vector<double>& a, int stride, int n, std::vector<double>& scratch) {
  const int half = n / 2;
  scratch.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));  // every entry is written below
  auto at = [&](int r, int c) -> double& { return a[static_cast<std::size_t>(r) * stride + c]; };
  auto out = [&](int r, int c) -> double& { return scratch[static_cast<std::size_t>(r) * n + c]; };
  for (int i = 0; i < half; ++i) {
    for (int j = 0; j < half; ++j) {
      const double p = at(2 * i, 2 * j), q = at(2 * i, 2 * j + 1);
      const double r = at(2 * i + 1, 2 * j), t = at(2 * i + 1, 2 * j + 1);
      out(i, j) = 0.5 * (p + q + r + t);
      out(i, j + half) = 0.5 * (p - q + r - t);  // h: along φ
      out(i + half, j) = 0.5 * (p + q - r - t);  // v: along θ
      out(i + half, j + half) = 0.5 * (p - q - r + t);
    }
  }
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) at(r, c) = out(r, c);
}

static void synthesisStep(std::vector<double>& a, int stride, int n, std::vector<double>& scratch) {
  const int half = n / 2;
  scratch.resize(static_cast<std::size_t>(n) * static_cast<std::size_t>(n));  // every entry is written below
  auto at = [&](int r, int c) -> double& { return a[static_cast<std::size_t>(r) * stride + c]; };
  auto out = [&](int r, int c) -> double& { return scratch[static_cast<std::size_t>(r) * n + c]; };
  for (int i = 0; i < half; ++i) {
    for (int j = 0; j < half; ++j) {
      const double s = at(i, j), h = at(i, j + half), v = at(i + half, j), d = at(i + half, j + half);
      out(2 * i, 2 * j) = 0.5 * (s + h + v + d);
      out(2 * i, 2 * j + 1) = 0.5 * (s - h + v - d);
      out(2 * i + 1, 2 * j) = 0.5 * (s + h - v - d);
      out(2 * i + 1, 2 * j + 1) = 0.5 * (s - h - v + d);
    }
  }
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) at(r, c) = out(r, c);
}

// Per-thread work buffers: at level 7 and above a map of doubles passes
// glibc's mmap threshold, and a fresh buffer per call would cost page faults
// (measured: forward transform 25× slower at level 7 than at level 6).
struct TransformBuffers {
  std::vector<double> a, scratch;
};
static TransformBuffers& buffers() {
  thread_local TransformBuffers b;
  return b;
}

HaarMap forwardHaar(const SphereMap& map) {
  const int m = map.size();
  auto& [a, scratch] = buffers();
  a.assign(map.values().begin(), map.values().end());
  for (int n = m; n >= 2; n /= 2) analysisStep(a, m, n, scratch);
  HaarMap out(map.level());
  std::transform(a.begin(), a.end(), out.coefficients().begin(), [](double x) { return static_cast<float>(x); });
  return out;
}

SphereMap inverseHaar(const HaarMap& coeffs) {
  const int m = coeffs.size();
  auto& [a, scratch] = buffers();
  a.assign(coeffs.coefficients().begin(), coeffs.coefficients().end());
  for (int n = 2; n <= m; n *= 2) synthesisStep(a, m, n, scratch);
  SphereMap out(coeffs.level());
  std::transform(a.begin(), a.end(), out.values().begin(), [](double x) { return static_cast<float>(x); });
  return out;
}

std::vector<double> scalingValues(const HaarMap& coeffs, int l) {
  std::vector<double> a, scratch;
  scalingValues(coeffs, l, a, scratch);
  return a;
}

void scalingValues(const HaarMap& coeffs, int l, std::vector<double>& a, std::vector<double>& scratch) {
  if (l < 0 || l > coeffs.level()) throw std::invalid_argument("scalingValues: level out of range");
  const int m = coeffs.size();
  const int side = 1 << l;
  // Synthesise only the top-left side×side corner: levels 0 .. l−1.
  a.resize(static_cast<std::size_t>(side) * static_cast<std::size_t>(side));
  for (int r = 0; r < side; ++r)
    for (int c = 0; c < side; ++c)
      a[static_cast<std::size_t>(r) * side + c] = coeffs[static_cast<std::size_t>(r) * m + c];
  for (int n = 2; n <= side; n *= 2) synthesisStep(a, side, n, scratch);
}

HaarMap SparseHaar::toDense() const {
  HaarMap dense(level);
  for (std::size_t k = 0; k < index.size(); ++k) dense[index[k]] = value[k];
  return dense;
}

SparseHaar SparseHaar::fromDense(const HaarMap& dense) {
  SparseHaar s;
  s.level = dense.level();
  for (std::size_t i = 0; i < dense.coefficientCount(); ++i) {
    if (dense[i] != 0.0f) {
      s.index.push_back(static_cast<std::uint32_t>(i));
      s.value.push_back(dense[i]);
    }
  }
  return s;
}

SparseHaar keepLargest(const HaarMap& coeffs, std::size_t k) {
  std::vector<std::uint32_t> order;
  std::vector<double> weight(coeffs.coefficientCount());
  for (std::size_t i = 0; i < coeffs.coefficientCount(); ++i) {
    if (coeffs[i] == 0.0f) continue;
    order.push_back(static_cast<std::uint32_t>(i));
    weight[i] = std::abs(static_cast<double>(coeffs[i])) * supportSide(coeffs.level(), i);
  }
  if (k < order.size()) {
    // Ties broken by index so that the choice is deterministic.
    std::nth_element(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(k), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) {
                       return weight[a] != weight[b] ? weight[a] > weight[b] : a < b;
                     });
    order.resize(k);
  }
  std::sort(order.begin(), order.end());
  SparseHaar s;
  s.level = coeffs.level();
  s.index = order;
  s.value.reserve(order.size());
  for (auto i : order) s.value.push_back(coeffs[i]);
  return s;
}

}  // namespace haarcast
