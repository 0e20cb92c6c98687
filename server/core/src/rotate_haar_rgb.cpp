// rotateHaar3: the Refined rotation of rotate_haar.cpp for three channels at
// once, with the geometry shared and the work buffers owned by the caller
// (rotate_haar.h, "Three colour channels at once"). Same notation as
// rotate_haar.cpp: a working map of side mw = 2^(start+1), pixel steps
// dθ = π/mw and dφ = 2π/mw, source positions in f's working-pixel coordinates
// (x along φ, y along θ, pixel centres at integers).
//
// Every per-channel quantity is stored interleaved, three doubles per entry
// (R, G, B), so that one pass over a field serves all three channels.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>

#include <glm/matrix.hpp>

#include "haarcast/core/rotate_haar.h"
#include "rotators.h"

namespace haarcast {
namespace {

constexpr std::size_t kChannels = 3;
// A source cell: f's θ-difference to the row below, φ-difference to the
// column right, and the mixed difference (φ-difference of the row below minus
// this row's), three channels each.
constexpr std::size_t kCellStride = 3 * kChannels;
constexpr std::size_t kT = 0, kP = kChannels, kM = 2 * kChannels;

std::size_t idx(int r, int c, int cols) {
  return static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c);
}

// std::floor without SSE4.1 is a library call; positions here are small.
double floorSmall(double x) {
  const double t = static_cast<double>(static_cast<long long>(x));
  return t > x ? t - 1.0 : t;
}

// ---- Per-level geometry, computed once ---------------------------------------

// sin and cos of every working pixel centre's θ and φ (rowTheta, colPhi of the
// working level): the pixel-centre directions p(θ, φ) without trigonometry.
struct CentreTrig {
  std::vector<double> sinTheta, cosTheta, sinPhi, cosPhi;
};

const CentreTrig& centreTrig(int workingLevel) {
  static std::array<std::once_flag, kMaxLevel + 1> once;
  static std::array<CentreTrig, kMaxLevel + 1> tables;
  const auto w = static_cast<std::size_t>(workingLevel);
  std::call_once(once[w], [&] {
    const int mw = mapSize(workingLevel);
    const double dT = kPi / mw, dP = kTwoPi / mw;
    CentreTrig& t = tables[w];
    for (int k = 0; k < mw; ++k) {
      t.sinTheta.push_back(std::sin((k + 0.5) * dT));
      t.cosTheta.push_back(std::cos((k + 0.5) * dT));
      t.sinPhi.push_back(std::sin((k + 0.5) * dP));
      t.cosPhi.push_back(std::cos((k + 0.5) * dP));
    }
  });
  return tables[w];
}

// Source position of every working pixel centre: s = Rᵀp = sinθ·(sinφ·Rᵀx̂ +
// cosφ·Rᵀẑ) + cosθ·Rᵀŷ, then Θ = acos(s_y), Φ = atan2(s_x, s_z) ∈ [0, 2π)
// (directionToSpherical), in f's working-pixel coordinates.
void sourcePositions(const glm::dmat3& rt, int mw, std::vector<double>& points) {
  const CentreTrig& trig = centreTrig(std::countr_zero(static_cast<unsigned>(mw)));
  const double toX = mw / kTwoPi, toY = mw / kPi;
  points.resize(2 * static_cast<std::size_t>(mw) * static_cast<std::size_t>(mw));
  const glm::dvec3 up = rt[1];
  for (int c = 0; c < mw; ++c) {
    const glm::dvec3 across = trig.sinPhi[static_cast<std::size_t>(c)] * rt[0] + trig.cosPhi[static_cast<std::size_t>(c)] * rt[2];
    for (int r = 0; r < mw; ++r) {
      const glm::dvec3 s = trig.sinTheta[static_cast<std::size_t>(r)] * across + trig.cosTheta[static_cast<std::size_t>(r)] * up;
      double phi = std::atan2(s.x, s.z);
      if (phi < 0.0) phi += kTwoPi;
      if (phi >= kTwoPi) phi -= kTwoPi;
      const double theta = std::acos(std::clamp(s.y, -1.0, 1.0));
      double* p = &points[2 * idx(r, c, mw)];
      p[0] = phi * toX - 0.5;
      p[1] = theta * toY - 0.5;
    }
  }
}

// ---- Step (1): f's exact differences per source cell, one channel -----------

// As exactDifferences in rotate_haar.cpp: inside each 2×2 block from the
// start level's details, across blocks from its scaling values. Writes
// channel ch of every cell and returns f at working pixel (row0, col0).
double sourceCells(const HaarMap& f, int start, std::size_t ch, int row0, int col0, HaarRotationScratch& s) {
  const int mw = 2 << start, half = mw / 2, m = f.size();
  const double scale = 1.0 / static_cast<double>(1 << (f.level() - (start + 1)));
  scalingValues(f, start, s.scaling, s.synthesis);
  const std::vector<double>& sv = s.scaling;
  auto S = [&](int i, int j) { return sv[idx(i, j, half)] * scale; };
  auto H = [&](int i, int j) { return static_cast<double>(f[idx(i, half + j, m)]) * scale; };
  auto V = [&](int i, int j) { return static_cast<double>(f[idx(half + i, j, m)]) * scale; };
  auto D = [&](int i, int j) { return static_cast<double>(f[idx(half + i, half + j, m)]) * scale; };
  double* cells = s.cells.data();
  auto cell = [&](int row, int col) { return cells + idx(row, col, mw) * kCellStride; };

  // Inside each block, corners a b / c d: c − a = −v − d', d − b = −v + d',
  // b − a = −h − d', d − c = −h + d'.
  for (int i = 0; i < half; ++i)
    for (int j = 0; j < half; ++j) {
      const double h = H(i, j), v = V(i, j), d = D(i, j);
      cell(2 * i, 2 * j)[kT + ch] = -v - d;
      cell(2 * i, 2 * j + 1)[kT + ch] = -v + d;
      cell(2 * i, 2 * j)[kP + ch] = -h - d;
      cell(2 * i + 1, 2 * j)[kP + ch] = -h + d;
    }
  // Across block boundaries (acrossBlockDifferences in rotate_haar.cpp).
  for (int i = 0; i + 1 < half; ++i)
    for (int j = 0; j < half; ++j) {
      const double ds = S(i + 1, j) - S(i, j);
      const double dh = H(i + 1, j) - H(i, j), sumV = V(i + 1, j) + V(i, j), sumD = D(i + 1, j) + D(i, j);
      cell(2 * i + 1, 2 * j)[kT + ch] = 0.5 * (ds + dh + sumV + sumD);
      cell(2 * i + 1, 2 * j + 1)[kT + ch] = 0.5 * (ds - dh + sumV - sumD);
    }
  for (int i = 0; i < half; ++i)
    for (int j = 0; j < half; ++j) {
      const int jn = (j + 1) % half;
      const double ds = S(i, jn) - S(i, j);
      const double sumH = H(i, jn) + H(i, j), dv = V(i, jn) - V(i, j), sumD = D(i, jn) + D(i, j);
      cell(2 * i, 2 * j + 1)[kP + ch] = 0.5 * (ds + sumH + dv + sumD);
      cell(2 * i + 1, 2 * j + 1)[kP + ch] = 0.5 * (ds + sumH - dv - sumD);
    }
  // Mixed differences; the last row has no row below.
  for (int row = 0; row < mw; ++row)
    for (int col = 0; col < mw; ++col) {
      double* c = cell(row, col);
      if (row + 1 < mw) {
        c[kM + ch] = cell(row + 1, col)[kP + ch] - c[kP + ch];
      } else {
        c[kT + ch] = 0.0;
        c[kM + ch] = 0.0;
      }
    }
  // Pixel (row, col) of block (i, j): a, b, c, d = (s ± h ± v ± d')/2.
  const int i = row0 / 2, j = col0 / 2;
  const double sh = col0 % 2 ? -1.0 : 1.0, sv0 = row0 % 2 ? -1.0 : 1.0;
  return 0.5 * (S(i, j) + sh * H(i, j) + sv0 * V(i, j) + sh * sv0 * D(i, j));
}

// ---- Step (2): the finite chain rule, walked once for three channels --------

// f(S(p₂)) − f(S(p₁)) for the three channels: finiteChainRule's `difference`
// in rotate_haar.cpp (the path in (x, y), x the short way round, split where
// it crosses a cell line; each cell adds its bilinear terms). The walk, and
// each cell's weights, are shared by the channels. The cell is tracked by
// stepping across the lines as they are crossed (each axis's crossings are
// evenly spaced in the path parameter), not found again per piece.
void chainDifference(const double* cells, int mw, const double* a, const double* b, double* out) {
  double dx = b[0] - a[0];
  const double halfMw = 0.5 * mw;
  if (dx >= halfMw) dx -= mw;
  else if (dx <= -halfMw) dx += mw;
  const double dy = b[1] - a[1];
  // Start cell: the one the path enters (a start on a line going down-axis
  // lies in the cell below it), the parameter of each axis's next crossing,
  // and the step between crossings.
  constexpr double kNever = 2.0;
  struct Axis {
    double cell, next, step;
    int dir;
  };
  auto axis = [](double p0, double dp) {
    const double f = floorSmall(p0);
    if (dp > 0.0) return Axis{f, (f + 1.0 - p0) / dp, 1.0 / dp, 1};
    if (dp < 0.0) {
      const double c = f == p0 ? f - 1.0 : f;  // ceil(p0) − 1
      return Axis{c, (c - p0) / dp, -1.0 / dp, -1};
    }
    return Axis{f, kNever, 0.0, 0};
  };
  Axis ax = axis(a[0], dx), ay = axis(a[1], dy);
  const unsigned wrap = static_cast<unsigned>(mw) - 1u;
  int col = static_cast<int>(static_cast<unsigned>(static_cast<int>(ax.cell)) & wrap);
  int row = static_cast<int>(ay.cell);
  double x0 = a[0] - ax.cell, y0 = a[1] - ay.cell;
  double sum0 = 0.0, sum1 = 0.0, sum2 = 0.0;
  for (;;) {
    const double s1 = std::min({ax.next, ay.next, 1.0});
    const double x1 = a[0] + s1 * dx - ax.cell, y1 = a[1] + s1 * dy - ay.cell;
    if (row < 0 || row >= mw - 1) {
      // Beyond the first and last row centres θ is clamped: only dφ acts.
      const double* c = cells + idx(row < 0 ? 0 : mw - 1, col, mw) * kCellStride + kP;
      const double wx = x1 - x0;
      sum0 += wx * c[0];
      sum1 += wx * c[1];
      sum2 += wx * c[2];
    } else {
      const double wy = y1 - y0, wx = x1 - x0, wxy = x1 * y1 - x0 * y0;
      const double* c = cells + idx(row, col, mw) * kCellStride;
      sum0 += wy * c[kT + 0] + wx * c[kP + 0] + wxy * c[kM + 0];
      sum1 += wy * c[kT + 1] + wx * c[kP + 1] + wxy * c[kM + 1];
      sum2 += wy * c[kT + 2] + wx * c[kP + 2] + wxy * c[kM + 2];
    }
    if (s1 >= 1.0) break;
    x0 = x1;
    y0 = y1;
    if (ax.next <= s1) {  // into the next column: same point, new cell coordinates
      ax.cell += ax.dir;
      x0 -= ax.dir;
      col = static_cast<int>(static_cast<unsigned>(col + ax.dir) & wrap);
      ax.next += ax.step;
    }
    if (ay.next <= s1) {
      ay.cell += ay.dir;
      y0 -= ay.dir;
      row += ay.dir;
      ay.next += ay.step;
    }
  }
  out[0] = sum0;
  out[1] = sum1;
  out[2] = sum2;
}

// ---- Seed eqs. 14–16, recursively, three channels ---------------------------

// triangleBoxSums of rotate_haar.cpp on a three-channel field F(a, c) at
// field + 3·(a·strideA + c·strideC): a along the triangle axis (mw−1
// boundaries), c along the box axis (mw pixels). emit(l, a, b, sums) for
// every detail level l ≤ finest and block (a, b), a along the triangle axis.
template <typename Emit>
void triangleBoxSums3(const double* field, std::size_t strideA, std::size_t strideC, int mw, int finest,
                      HaarRotationScratch& s, Emit emit) {
  s.sumsA.resize(static_cast<std::size_t>(mw - 1) * static_cast<std::size_t>(mw / 2) * kChannels);
  s.sumsB.resize(s.sumsA.size());
  double* t = s.sumsA.data();
  double* next = s.sumsB.data();
  const int half = mw / 2;
  for (int a = 0; a + 1 < mw; ++a)
    for (int b = 0; b < half; ++b) {
      const double* f0 = field + kChannels * (static_cast<std::size_t>(a) * strideA + static_cast<std::size_t>(2 * b) * strideC);
      const double* f1 = f0 + kChannels * strideC;
      double* o = t + kChannels * idx(a, b, half);
      for (std::size_t ch = 0; ch < kChannels; ++ch) o[ch] = f0[ch] + f1[ch];
    }
  // t(a, b): rows a ∈ [0, 2·blocks − 1), columns b ∈ [0, blocks).
  for (int l = finest;; --l) {
    const int blocks = 1 << l;
    for (int a = 0; a < blocks; ++a)
      for (int b = 0; b < blocks; ++b) emit(l, a, b, t + kChannels * idx(2 * a, b, blocks));
    if (l == 0) break;
    const int cols = blocks / 2;
    for (int a = 0; a + 1 < blocks; ++a)
      for (int b = 0; b < cols; ++b) {
        double* o = next + kChannels * idx(a, b, cols);
        for (std::size_t ch = 0; ch < kChannels; ++ch) {
          double sum = 0.0;
          for (int q = 0; q < 2; ++q) {
            sum += t[kChannels * idx(2 * a, 2 * b + q, blocks) + ch] + 2.0 * t[kChannels * idx(2 * a + 1, 2 * b + q, blocks) + ch] +
                   t[kChannels * idx(2 * a + 2, 2 * b + q, blocks) + ch];
          }
          o[ch] = sum;
        }
      }
    std::swap(t, next);
  }
}

// triangleTriangleSums of rotate_haar.cpp: triangle kernels along both axes
// of the (mw−1)² three-channel field (the diagonal band).
template <typename Emit>
void triangleTriangleSums3(const double* field, int finest, HaarRotationScratch& s, Emit emit) {
  const int blocks0 = 1 << finest;
  const std::size_t size = blocks0 > 1 ? static_cast<std::size_t>(blocks0 - 1) * static_cast<std::size_t>(blocks0 - 1) * kChannels : 0;
  s.sumsA.resize(std::max(s.sumsA.size(), size));
  s.sumsB.resize(std::max(s.sumsB.size(), size));
  const double* q = field;
  double* bufs[2] = {s.sumsA.data(), s.sumsB.data()};
  int which = 0;
  static constexpr double w[3] = {1.0, 2.0, 1.0};
  for (int l = finest;; --l) {
    const int blocks = 1 << l, side = 2 * blocks - 1;
    for (int a = 0; a < blocks; ++a)
      for (int b = 0; b < blocks; ++b) emit(l, a, b, q + kChannels * idx(2 * a, 2 * b, side));
    if (l == 0) break;
    double* next = bufs[which];
    which ^= 1;
    for (int a = 0; a + 1 < blocks; ++a)
      for (int b = 0; b + 1 < blocks; ++b) {
        double sum[kChannels] = {0.0, 0.0, 0.0};
        for (int p = 0; p < 3; ++p)
          for (int r = 0; r < 3; ++r) {
            const double* x = q + kChannels * idx(2 * a + p, 2 * b + r, side);
            for (std::size_t ch = 0; ch < kChannels; ++ch) sum[ch] += w[p] * w[r] * x[ch];
          }
        double* o = next + kChannels * idx(a, b, blocks - 1);
        for (std::size_t ch = 0; ch < kChannels; ++ch) o[ch] = sum[ch];
      }
    q = next;
  }
}

void checkInputs(const std::array<const HaarMap*, 3>& f, const HaarRotationOptions& options) {
  for (std::size_t c = 0; c < kChannels; ++c) {
    if (!f[c]) throw std::invalid_argument("rotateHaar3: channel " + std::to_string(c) + " map is null");
    if (f[c]->level() != f[0]->level()) {
      throw std::invalid_argument("rotateHaar3: channel " + std::to_string(c) + " has level " +
                                  std::to_string(f[c]->level()) + ", channel 0 level " + std::to_string(f[0]->level()));
    }
  }
  const int n = f[0]->level();
  if (n >= 1 && options.startLevel > n - 1) {
    throw std::invalid_argument("rotateHaar3: start level " + std::to_string(options.startLevel) +
                                " is finer than the map's finest detail level " + std::to_string(n - 1));
  }
}

}  // namespace

void rotateHaar3(const std::array<const HaarMap*, 3>& f, const EulerYXY& r, std::array<HaarMap, 3>& out,
                 HaarRotationScratch& s, const HaarRotationOptions& options) {
  checkInputs(f, options);
  const int n = f[0]->level();
  if (n < 1) {  // a 1×1 map is a constant: every rotation leaves it.
    for (std::size_t c = 0; c < kChannels; ++c) out[c] = *f[c];
    return;
  }
  if (options.variant != HaarVariant::Refined) {
    for (std::size_t c = 0; c < kChannels; ++c) out[c] = rotateHaar(*f[c], r, options);
    return;
  }
  const int start = options.startLevel < 0 ? n - 1 : options.startLevel;
  const int mw = 2 << start;
  const glm::dmat3 rt = glm::transpose(rotationMatrix(r));

  // Geometry, once: the source of every working pixel centre.
  sourcePositions(rt, mw, s.points);
  auto at = [&](int row, int col) { return &s.points[2 * idx(row, col, mw)]; };

  // Step (1) per channel, and the anchor of step (3): f at the source of g's
  // first pixel, bilinear as everywhere.
  s.cells.resize(static_cast<std::size_t>(mw) * static_cast<std::size_t>(mw) * kCellStride);
  const double* p0 = at(0, 0);
  const double y0 = std::clamp(p0[1], 0.0, static_cast<double>(mw - 1));
  const int r0 = std::min(static_cast<int>(y0), mw - 2);
  const double fx = floorSmall(p0[0]);
  const int c0 = static_cast<int>(static_cast<unsigned>(static_cast<int>(fx)) & static_cast<unsigned>(mw - 1));
  const double tx = p0[0] - fx, ty = y0 - r0;
  std::array<double, kChannels> anchor{};
  for (std::size_t c = 0; c < kChannels; ++c) {
    const double pixel = sourceCells(*f[c], start, c, r0, c0, s);
    const double* cell = &s.cells[idx(r0, c0, mw) * kCellStride];
    anchor[c] = pixel + ty * cell[kT + c] + tx * cell[kP + c] + tx * ty * cell[kM + c];
  }

  // Step (2), once for the three channels: g's differences.
  const std::size_t mwz = static_cast<std::size_t>(mw);
  s.dTheta.resize((mwz - 1) * mwz * kChannels);
  s.dPhi.resize(mwz * (mwz - 1) * kChannels);
  s.dMixed.resize((mwz - 1) * (mwz - 1) * kChannels);
  const double* cells = s.cells.data();
  for (int t = 0; t + 1 < mw; ++t)
    for (int c = 0; c < mw; ++c) chainDifference(cells, mw, at(t, c), at(t + 1, c), &s.dTheta[kChannels * idx(t, c, mw)]);
  // φ-differences: walked along the first row only. Each difference is
  // F(S(p₂)) − F(S(p₁)) of the continuous bilinear model F, so the four
  // differences around any four pixels sum to zero exactly (the discrete
  // equality of mixed partials behind seed eq. 13), and every further row
  // follows from the one above: dPhi(r, u) = dPhi(r−1, u) + dTheta(r−1, u+1)
  // − dTheta(r−1, u). Same numbers up to double rounding, half the walks.
  for (int u = 0; u + 1 < mw; ++u) chainDifference(cells, mw, at(0, u), at(0, u + 1), &s.dPhi[kChannels * idx(0, u, mw - 1)]);
  for (int row = 1; row < mw; ++row)
    for (int u = 0; u + 1 < mw; ++u) {
      const double* above = &s.dPhi[kChannels * idx(row - 1, u, mw - 1)];
      const double* left = &s.dTheta[kChannels * idx(row - 1, u, mw)];
      double* o = &s.dPhi[kChannels * idx(row, u, mw - 1)];
      for (std::size_t c = 0; c < kChannels; ++c) o[c] = above[c] + left[kChannels + c] - left[c];
    }
  // The diagonal band from the θ-difference of the φ-differences.
  for (std::size_t k = 0; k < s.dMixed.size(); ++k) s.dMixed[k] = s.dPhi[k + kChannels * (mwz - 1)] - s.dPhi[k];

  // Step (3): g's scaling coefficient from the anchor and g's summed differences.
  std::array<double, kChannels> total{}, rowStart = anchor;
  for (int row = 0; row < mw; ++row)
    for (std::size_t c = 0; c < kChannels; ++c) {
      if (row > 0) rowStart[c] += s.dTheta[kChannels * idx(row - 1, 0, mw) + c];
      double value = rowStart[c];
      double sum = value;
      for (int u = 1; u < mw; ++u) {
        value += s.dPhi[kChannels * idx(row, u - 1, mw - 1) + c];
        sum += value;
      }
      total[c] += sum;
    }

  // Details of g: v = −Σ/side, h = −Σ/side, d' = Σ/side, side in working
  // pixels; × 2^(n−w) back to the level-n normalisation. Both factors are
  // powers of two, so one product is exact.
  const int m = mapSize(n);
  for (std::size_t c = 0; c < kChannels; ++c) {
    if (out[c].level() != n) out[c] = HaarMap(n);
    if (start < n - 1) std::fill(out[c].coefficients().begin(), out[c].coefficients().end(), 0.0f);
  }
  const double up = static_cast<double>(1 << (n - (start + 1)));
  auto factor = [&](int l) { return up / static_cast<double>(mw >> l); };
  auto store = [&](Band band, int l, int i, int j, const double* sums, double k) {
    const std::size_t index = HaarMap::detailIndexOf(m, band, l, i, j);
    for (std::size_t c = 0; c < kChannels; ++c) out[c][index] = static_cast<float>(sums[c] * k);
  };
  triangleBoxSums3(s.dTheta.data(), mwz, 1, mw, start, s, [&](int l, int a, int b, const double* sums) {
    store(Band::Vertical, l, a, b, sums, -factor(l));
  });
  triangleBoxSums3(s.dPhi.data(), 1, mwz - 1, mw, start, s, [&](int l, int a, int b, const double* sums) {
    store(Band::Horizontal, l, b, a, sums, -factor(l));
  });
  triangleTriangleSums3(s.dMixed.data(), start, s, [&](int l, int a, int b, const double* sums) {
    store(Band::Diagonal, l, a, b, sums, factor(l));
  });
  for (std::size_t c = 0; c < kChannels; ++c) out[c].scaling() = static_cast<float>(total[c] / mw * up);
}

// ---- RgbHaarRotator -----------------------------------------------------------

RgbHaarRotator::RgbHaarRotator(std::array<std::vector<HaarMap>, 3> channelSlices, const HaarRotationOptions& options)
    : slices_(std::move(channelSlices)), options_(options) {
  for (std::size_t c = 0; c < kChannels; ++c) {
    detail::checkSlices(slices_[c], "RgbHaarRotator");
    if (slices_[c].size() != slices_[0].size()) {
      throw std::invalid_argument("RgbHaarRotator: channel " + std::to_string(c) + " has " +
                                  std::to_string(slices_[c].size()) + " slices, channel 0 has " +
                                  std::to_string(slices_[0].size()));
    }
    if (slices_[c].front().level() != slices_[0].front().level()) {
      throw std::invalid_argument("RgbHaarRotator: channel " + std::to_string(c) + " is level " +
                                  std::to_string(slices_[c].front().level()) + ", channel 0 level " +
                                  std::to_string(slices_[0].front().level()));
    }
  }
  const int n = level();
  if (options_.startLevel > n - 1) {
    throw std::invalid_argument("RgbHaarRotator: start level " + std::to_string(options_.startLevel) +
                                " is finer than the slices' finest detail level " + std::to_string(n - 1));
  }
}

RgbHaarRotator::RgbHaarRotator(std::array<std::vector<HaarMap>, 3> channelSlices, const RotatorOptions& options)
    : RgbHaarRotator(std::move(channelSlices), HaarRotationOptions{options.haarVariant, options.haarStartLevel}) {}

void RgbHaarRotator::rotate(std::size_t slice, const EulerYXY& r, std::array<HaarMap, 3>& out,
                            HaarRotationScratch& scratch) const {
  rotateHaar3({&slices_[0].at(slice), &slices_[1].at(slice), &slices_[2].at(slice)}, r, out, scratch, options_);
}

std::size_t RgbHaarRotator::storedBytes() const {
  std::size_t bytes = 0;
  for (const auto& channel : slices_) bytes += detail::coefficientBytes(channel);
  return bytes;
}

}  // namespace haarcast
