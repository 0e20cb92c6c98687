// The reference's sampling primitives (reference.h "Sampling"): PCG32
// random streams, piecewise-constant distributions on the sphere in the
// haarcast direction convention, and the cell maxima that feed them.
// Internal to haarcast_cpu; header-only so that reference.cpp stays one
// idea (the estimator) and these stay another.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#include "haarcast/core/parallel.h"
#include "haarcast/core/sphere_map.h"

namespace haarcast::render::reference_sampling {

// ---- Random numbers -------------------------------------------------------

inline std::uint64_t splitMix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// PCG32 (O'Neill 2014, pcg32_random_r): 64-bit LCG state, XSH-RR output,
// one stream per odd increment.
class Pcg32 {
 public:
  Pcg32(std::uint64_t state, std::uint64_t stream) : inc_((stream << 1u) | 1u) {
    next();
    state_ += state;
    next();
  }
  std::uint32_t next() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    const auto xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const auto rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  double uniform() { return next() * 0x1p-32; }  // [0, 1)

 private:
  std::uint64_t state_ = 0;
  std::uint64_t inc_;
};

// ---- Piecewise-constant distributions on (part of) the sphere -------------

inline double channelMean(const glm::dvec3& c) {
  const double m = (c.x + c.y + c.z) / 3.0;
  return std::isfinite(m) && m > 0.0 ? m : 0.0;
}

// Rows over θ ∈ [0, θmax], columns over φ ∈ [0, 2π), the haarcast direction
// convention. Each cell holds a value per unit solid angle; a cell is chosen
// with probability value × (exact cell solid angle) / total, and a direction
// uniformly in solid angle inside it, so p(ω) = value(cell)/total.
class SphereDistribution {
 public:
  struct Sample {
    glm::dvec3 direction;
    double pdf;
  };

  // values: rows × cols, finite and ≥ 0, with a positive total.
  SphereDistribution(int rows, int cols, double thetaMax, std::vector<double> values)
      : rows_(rows), cols_(cols), thetaMax_(thetaMax), values_(std::move(values)) {
    cosEdge_ = edges(rows, thetaMax);
    rowCdf_.assign(static_cast<std::size_t>(rows) + 1, 0.0);
    colCdf_.assign(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols + 1), 0.0);
    const double dPhi = kTwoPi / cols;
    for (int r = 0; r < rows; ++r) {
      double* cdf = &colCdf_[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols + 1)];
      for (int c = 0; c < cols; ++c) cdf[c + 1] = cdf[c] + value(r, c);
      const double cellSolidAngle = (cosEdge_[static_cast<std::size_t>(r)] - cosEdge_[static_cast<std::size_t>(r) + 1]) * dPhi;
      rowCdf_[static_cast<std::size_t>(r) + 1] = rowCdf_[static_cast<std::size_t>(r)] + cdf[cols] * cellSolidAngle;
    }
    total_ = rowCdf_.back();
    if (!(total_ > 0.0) || !std::isfinite(total_)) throw std::logic_error("reference: a sampling table has no mass");
  }

  // cos θ at the row boundaries θ_r = r·θmax/rows, r = 0..rows.
  static std::vector<double> edges(int rows, double thetaMax) {
    std::vector<double> e(static_cast<std::size_t>(rows) + 1);
    for (int r = 0; r <= rows; ++r) e[static_cast<std::size_t>(r)] = std::cos(r * thetaMax / rows);
    return e;
  }

  Sample sample(double u1, double u2, double u3, double u4) const {
    // Row: the first whose cumulative mass exceeds u1·total (never an empty one).
    const double target = u1 * total_;
    auto it = std::upper_bound(rowCdf_.begin() + 1, rowCdf_.end(), target);
    const int r = std::min(static_cast<int>(it - (rowCdf_.begin() + 1)), rows_ - 1);
    const double* cdf = &colCdf_[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols_ + 1)];
    auto jt = std::upper_bound(cdf + 1, cdf + cols_ + 1, u2 * cdf[cols_]);
    const int c = std::min(static_cast<int>(jt - (cdf + 1)), cols_ - 1);
    const double c0 = cosEdge_[static_cast<std::size_t>(r)], c1 = cosEdge_[static_cast<std::size_t>(r) + 1];
    const double cosTheta = c0 + u3 * (c1 - c0);
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    const double phi = (c + u4) * kTwoPi / cols_;
    return {{sinTheta * std::sin(phi), cosTheta, sinTheta * std::cos(phi)}, value(r, c) / total_};
  }

  double pdf(const glm::dvec3& d) const { return pdfOfCell(cellOf(d)); }

  // The cell holding unit direction d (row-major index), or −1 beyond θmax.
  // Distributions of the same shape share cells: look up once, read many.
  std::ptrdiff_t cellOf(const glm::dvec3& d) const {
    const double theta = std::acos(std::clamp(d.y, -1.0, 1.0));
    if (theta >= thetaMax_) return -1;
    double phi = std::atan2(d.x, d.z);
    if (phi < 0.0) phi += kTwoPi;
    const int r = std::min(static_cast<int>(theta / thetaMax_ * rows_), rows_ - 1);
    const int c = std::min(static_cast<int>(phi / kTwoPi * cols_), cols_ - 1);
    return static_cast<std::ptrdiff_t>(r) * cols_ + c;
  }
  double pdfOfCell(std::ptrdiff_t cell) const {
    return cell < 0 ? 0.0 : values_[static_cast<std::size_t>(cell)] / total_;
  }

 private:
  double value(int r, int c) const {
    return values_[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols_) + static_cast<std::size_t>(c)];
  }

  int rows_, cols_;
  double thetaMax_;
  std::vector<double> values_;
  std::vector<double> cosEdge_;
  std::vector<double> rowCdf_;  // rows + 1, unnormalised mass
  std::vector<double> colCdf_;  // rows × (cols + 1), unnormalised values
  double total_ = 0.0;
};

// ---- Threads ----------------------------------------------------------------

// haarcast's pool, with the thread count where this file's calls put it.
inline void parallelFor(std::size_t count, unsigned threads, const std::function<void(std::size_t)>& body) {
  haarcast::parallelFor(count, body, {}, threads);
}

// The largest value of f over a 3×3 grid of directions in each cell, uniform
// in cos θ and φ and including the cell's edges and corners, rows over
// [0, θmax]. The grid points are shared with the neighbouring cells, so f is
// evaluated about 4 times per cell, not 9. A majorant rather than a mean:
// where f changes inside a cell (the limb of a small sun, the flank of a
// glossy lobe) a mean can sit far below f at some point of the cell, and f/p
// there becomes a firefly; the maximum keeps f/p near its ideal value.
inline std::vector<double> cellMaxima(int rows, int cols, double thetaMax, const std::function<double(const glm::dvec3&)>& f,
                               unsigned threads) {
  const std::vector<double> e = SphereDistribution::edges(rows, thetaMax);
  const int gridRows = 2 * rows + 1, gridCols = 2 * cols;  // φ wraps: no last column
  std::vector<double> grid(static_cast<std::size_t>(gridRows) * static_cast<std::size_t>(gridCols));
  parallelFor(static_cast<std::size_t>(gridRows), threads, [&](std::size_t gr) {
    const std::size_t r = gr / 2;
    const double cosTheta = gr % 2 == 0 ? e[r] : 0.5 * (e[r] + e[r + 1]);
    const double sinTheta = std::sqrt(std::max(0.0, 1.0 - cosTheta * cosTheta));
    for (int gc = 0; gc < gridCols; ++gc) {
      const double phi = gc * kTwoPi / gridCols;
      grid[gr * static_cast<std::size_t>(gridCols) + static_cast<std::size_t>(gc)] =
          f({sinTheta * std::sin(phi), cosTheta, sinTheta * std::cos(phi)});
    }
  });
  std::vector<double> out(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols));
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      double m = 0.0;
      for (int a = 0; a < 3; ++a) {
        const std::size_t row = static_cast<std::size_t>(2 * r + a) * static_cast<std::size_t>(gridCols);
        for (int b = 0; b < 3; ++b) m = std::max(m, grid[row + static_cast<std::size_t>((2 * c + b) % gridCols)]);
      }
      out[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c)] = m;
    }
  }
  return out;
}

}  // namespace haarcast::render::reference_sampling
