// matrix: the rotation-matrix baseline of Wang, Ng, Luebke, Humphreys 2006
// ("Efficient wavelet rotation for environment map rendering"). As the seed
// describes it, every wavelet is rotated spatially, transformed, and stored as
// one column of the rotation matrix of a discretised rotation; at run time the
// matrices of neighbouring samples are applied and interpolated.
//
// Wang et al. parameterise the sphere by geometry maps and so must sample
// whole rotations. On haarcast's lat-long maps a Y-X-Y rotation is
// g = shift_α ∘ elevate_β ∘ shift_γ (f) (rotation.h), and the φ-shifts are
// pixel permutations (exact for whole pixels, shiftPhi), so only elevate_β is
// tabulated: one N×N matrix per elevation β_k = kπ/(K−1), k = 0 … K−1. Column
// c of matrix k is rotateSpatial(e_c, {0, β_k, 0}), hence at a sample the
// method equals `spatial`; between samples it blends the two neighbouring
// matrices' products linearly in β, which is the interpolation error the seed
// holds against this method.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <span>
#include <string>
#include <tuple>
#include <vector>

#include "haarcast/core/rotation.h"
#include "haarcast/core/parallel.h"
#include "rotators.h"

namespace haarcast::detail {
namespace {

// Storage grows as K·N·(entries per column)·8 bytes, and a column keeps about
// 50 entries (measured with the default threshold: 46 at level 6, 49 at level
// 7, 50 at level 8; 33 elevations then take 50 MB, 210 MB and 870 MB), so
// level 9 would need about 3.5 GB. Past this budget the rotator refuses to
// precompute rather than exhaust memory; within it, a matrix's entry count
// stays far below the uint32 range of the CSR offsets.
constexpr double kEntriesPerColumn = 50.0;
constexpr double kMaxMatrixBytes = 2.0 * 1024 * 1024 * 1024;

// elevate_β on Haar coefficients, in compressed sparse rows (row = output
// coefficient), so that one output coefficient is one dot product.
struct CsrMatrix {
  std::vector<std::uint32_t> rowStart;  // N + 1 offsets into column/value
  std::vector<std::uint32_t> column;
  std::vector<float> value;

  std::size_t bytes() const {
    return rowStart.size() * sizeof(std::uint32_t) + column.size() * sizeof(std::uint32_t) +
           value.size() * sizeof(float);
  }
};

// Where each source pixel's value goes under the resampling that
// rotateSpatialMap performs for {0, β, 0}: target pixel p receives
// Σ weight · source. Stored per source pixel (the transpose of the bilinear
// stencils) so that the image of one basis function can be scattered from its
// support alone.
struct ElevationScatter {
  std::vector<std::uint32_t> start;  // pixelCount + 1 offsets, per source pixel
  std::vector<std::uint32_t> target;
  std::vector<double> weight;
};

ElevationScatter elevationScatter(int level, double beta) {
  const int m = mapSize(level);
  const std::size_t n = static_cast<std::size_t>(m) * static_cast<std::size_t>(m);
  struct Tap {
    std::uint32_t source;
    std::uint32_t target;
    double weight;
  };
  std::vector<Tap> taps;
  taps.reserve(4 * n);
  // The same source directions as rotateSpatialMap, and the same taps and
  // weights as SphereMap::sampleBilinear (bilinearTaps: φ wraps, θ clamps);
  // rotate_baselines_test checks columns against rotateSpatial.
  const glm::dmat3 rt = glm::transpose(rotationMatrix({0.0, beta, 0.0}));
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      const Spherical src = directionToSpherical(rt * sphericalToDirection(rowTheta(level, i), colPhi(level, j)));
      const BilinearTaps b = bilinearTaps(level, src.theta, src.phi);
      const auto target = static_cast<std::uint32_t>(i * m + j);
      for (int a = 0; a < 2; ++a) {
        for (int c = 0; c < 2; ++c) {
          const Tap t{static_cast<std::uint32_t>(b.row[a] * m + b.col[c]), target, b.weight(a, c)};
          if (t.weight != 0.0) taps.push_back(t);
        }
      }
    }
  }
  ElevationScatter s;
  s.start.assign(n + 1, 0);
  for (const Tap& t : taps) ++s.start[t.source + 1];
  for (std::size_t q = 0; q < n; ++q) s.start[q + 1] += s.start[q];
  s.target.assign(taps.size(), 0);
  s.weight.assign(taps.size(), 0.0);
  std::vector<std::uint32_t> fill(s.start.begin(), s.start.end() - 1);
  for (const Tap& t : taps) {
    const std::uint32_t k = fill[t.source]++;
    s.target[k] = t.target;
    s.weight[k] = t.weight;
  }
  return s;
}

// Workspace (one per matrix) that computes matrix columns: the image of one Haar
// basis function under the resampling, then its forward Haar transform done
// only over the pixels and blocks that the image touches. A basis function of
// detail level l covers (M/2^l)² pixels, so one column costs about its support
// plus the blocks above it, not N.
class ColumnBuilder {
 public:
  explicit ColumnBuilder(int level) : level_(level), grid_(level + 1), touched_(level + 1), mark_(level + 1) {
    for (int k = 0; k <= level; ++k) {
      const std::size_t cells = std::size_t{1} << (2 * k);
      grid_[k].assign(cells, 0.0);
      mark_[k].assign(cells, 0);
    }
  }

  // Appends the non-zero coefficients of elevate_β(ψ_c) as (row, value).
  void column(const ElevationScatter& scatter, std::size_t c, std::vector<std::uint32_t>& rows,
              std::vector<double>& values) {
    ++stamp_;
    scatterBasis(scatter, c);
    const int m = mapSize(level_);
    // Analysis as in forwardHaar, from 2^k × 2^k scaling values to 2^(k−1)
    // × 2^(k−1): the blocks touched at k−1 are the parents of those at k.
    for (int k = level_; k >= 1; --k) {
      const int side = 1 << k;
      const int half = side / 2;
      std::vector<double>& fine = grid_[k];
      std::vector<double>& coarse = grid_[k - 1];
      for (std::uint32_t p : touched_[k]) {
        const int r = static_cast<int>(p) / side, q = static_cast<int>(p) % side;
        touch(k - 1, static_cast<std::uint32_t>((r / 2) * half + q / 2));
      }
      for (std::uint32_t parent : touched_[k - 1]) {
        const int pi = static_cast<int>(parent) / half, pj = static_cast<int>(parent) % half;
        const std::size_t tl = static_cast<std::size_t>(2 * pi) * static_cast<std::size_t>(side) +
                               static_cast<std::size_t>(2 * pj);
        const double a = fine[tl], b = fine[tl + 1], cc = fine[tl + side], d = fine[tl + side + 1];
        coarse[parent] = 0.5 * (a + b + cc + d);
        emit(HaarMap::detailIndexOf(m, Band::Horizontal, k - 1, pi, pj), 0.5 * (a - b + cc - d), rows, values);
        emit(HaarMap::detailIndexOf(m, Band::Vertical, k - 1, pi, pj), 0.5 * (a + b - cc - d), rows, values);
        emit(HaarMap::detailIndexOf(m, Band::Diagonal, k - 1, pi, pj), 0.5 * (a - b - cc + d), rows, values);
      }
      for (std::uint32_t p : touched_[k]) fine[p] = 0.0;
      touched_[k].clear();
    }
    emit(0, grid_[0][0], rows, values);
    grid_[0][0] = 0.0;
    touched_[0].clear();
  }

 private:
  void touch(int k, std::uint32_t p) {
    if (mark_[k][p] != stamp_) {
      mark_[k][p] = stamp_;
      touched_[k].push_back(p);
    }
  }

  static void emit(std::size_t row, double v, std::vector<std::uint32_t>& rows, std::vector<double>& values) {
    if (v == 0.0) return;
    rows.push_back(static_cast<std::uint32_t>(row));
    values.push_back(v);
  }

  // Writes the resampled image of basis function c into grid_[level_]. The
  // basis function is what inverseHaar makes of e_c: ±1/side on a side×side
  // block (1/M everywhere for the scaling function); h changes sign along φ
  // (+ left), v along θ (+ top), d both.
  void scatterBasis(const ElevationScatter& scatter, std::size_t c) {
    const int m = mapSize(level_);
    const CoefficientPosition pos = coefficientPosition(level_, c);
    const int side = pos.isScaling ? m : m >> pos.level;
    const int row0 = pos.isScaling ? 0 : pos.i * side;
    const int col0 = pos.isScaling ? 0 : pos.j * side;
    const int half = side / 2;
    const double magnitude = 1.0 / side;
    std::vector<double>& image = grid_[level_];
    for (int r = 0; r < side; ++r) {
      for (int q = 0; q < side; ++q) {
        double v = magnitude;
        if (!pos.isScaling) {
          const bool left = q < half, top = r < half;
          const bool positive = pos.band == Band::Horizontal ? left
                                : pos.band == Band::Vertical ? top
                                                             : left == top;
          if (!positive) v = -v;
        }
        const auto source = static_cast<std::size_t>(row0 + r) * static_cast<std::size_t>(m) +
                            static_cast<std::size_t>(col0 + q);
        for (std::uint32_t e = scatter.start[source]; e < scatter.start[source + 1]; ++e) {
          image[scatter.target[e]] += v * scatter.weight[e];
          touch(level_, scatter.target[e]);
        }
      }
    }
  }

  int level_;
  std::vector<std::vector<double>> grid_;            // grid_[k]: 2^k × 2^k scaling values, zero between columns
  std::vector<std::vector<std::uint32_t>> touched_;  // cells of grid_[k] that may be non-zero
  std::vector<std::vector<std::uint32_t>> mark_;     // mark_[k][p] == stamp_: p is in touched_[k]
  std::uint32_t stamp_ = 0;
};

// The matrix of elevate_β, entries below threshold·(largest |entry|) dropped.
CsrMatrix elevationMatrix(int level, double beta, double threshold, ColumnBuilder& builder) {
  const ElevationScatter scatter = elevationScatter(level, beta);
  const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  // Columns first (that is how they are defined), then transposed to rows.
  std::vector<std::uint32_t> columnStart(n + 1, 0);
  std::vector<std::uint32_t> rows;
  std::vector<double> values;
  for (std::size_t c = 0; c < n; ++c) {
    builder.column(scatter, c, rows, values);
    columnStart[c + 1] = static_cast<std::uint32_t>(rows.size());
  }
  double largest = 0.0;
  for (double v : values) largest = std::max(largest, std::abs(v));
  const double cut = threshold * largest;
  CsrMatrix a;
  a.rowStart.assign(n + 1, 0);
  for (std::size_t e = 0; e < rows.size(); ++e)
    if (std::abs(values[e]) >= cut) ++a.rowStart[rows[e] + 1];
  for (std::size_t r = 0; r < n; ++r) a.rowStart[r + 1] += a.rowStart[r];
  a.column.resize(a.rowStart[n]);
  a.value.resize(a.rowStart[n]);
  std::vector<std::uint32_t> fill(a.rowStart.begin(), a.rowStart.end() - 1);
  // Walking columns in order leaves every row's entries sorted by column.
  for (std::size_t c = 0; c < n; ++c) {
    for (std::uint32_t e = columnStart[c]; e < columnStart[c + 1]; ++e) {
      if (std::abs(values[e]) < cut) continue;
      const std::uint32_t k = fill[rows[e]]++;
      a.column[k] = static_cast<std::uint32_t>(c);
      a.value[k] = static_cast<float>(values[e]);
    }
  }
  return a;
}

// All K matrices, one elevation per task on hardware_concurrency threads.
std::vector<CsrMatrix> elevationMatrices(int level, int count, double threshold) {
  std::vector<CsrMatrix> matrices(static_cast<std::size_t>(count));
  parallelFor(matrices.size(), [&](std::size_t i) {
    const int k = static_cast<int>(i);
    const double beta = kPi * k / (count - 1);
    ColumnBuilder builder(level);
    matrices[i] = elevationMatrix(level, beta, threshold, builder);
  });
  return matrices;
}

// The matrices depend on the level and the options only, not on the slices:
// every rotator alive with the same ones shares them (the three channels of
// an object, and every object of a scene), built once.
std::shared_ptr<const std::vector<CsrMatrix>> sharedElevationMatrices(int level, int count, double threshold) {
  using Key = std::tuple<int, int, double>;
  static std::mutex mutex;
  static std::map<Key, std::weak_ptr<const std::vector<CsrMatrix>>> cache;
  const Key key{level, count, threshold};
  {
    std::lock_guard lock(mutex);
    if (auto alive = cache[key].lock()) return alive;
  }
  // Built outside the lock (seconds at level 6); two callers racing for the
  // same key may both build, and the first one stored is shared from then on.
  auto built = std::make_shared<const std::vector<CsrMatrix>>(elevationMatrices(level, count, threshold));
  std::lock_guard lock(mutex);
  if (auto alive = cache[key].lock()) return alive;
  cache[key] = built;
  return built;
}

class MatrixRotator final : public SliceRotator {
 public:
  MatrixRotator(std::vector<HaarMap> slices, const RotatorOptions& options)
      : slices_(std::move(slices)),
        shared_(sharedElevationMatrices(slices_.front().level(), options.matrixElevations, options.matrixThreshold)),
        matrices_(*shared_) {}

  RotationMethod method() const override { return RotationMethod::Matrix; }
  std::size_t sliceCount() const override { return slices_.size(); }
  int level() const override { return slices_.front().level(); }

  void rotate(std::size_t slice, const EulerYXY& r, HaarMap& out) const override {
    const HaarMap& f = slices_.at(slice);
    // Bring β into [0, π]: R_x(−b) = R_y(π) R_x(b) R_y(−π), so (α, −b, γ) is
    // (α + π, b, γ − π) — still whole pixels if α and γ were (M is even).
    double alpha = r.alpha, beta = std::remainder(r.beta, kTwoPi), gamma = r.gamma;
    if (beta < 0.0) {
      alpha += kPi;
      gamma -= kPi;
      beta = -beta;
    }
    const HaarMap turned = shiftPhi(f, gamma);
    const int last = static_cast<int>(matrices_.size()) - 1;
    const double u = beta / kPi * last;
    // A β that is a sample up to rounding uses that matrix alone.
    const double nearest = std::round(u);
    int k;
    double t;
    if (std::abs(u - nearest) < 1e-9) {
      k = static_cast<int>(nearest);
      t = 0.0;
    } else {
      k = std::min(static_cast<int>(std::floor(u)), last - 1);
      t = u - k;
    }
    HaarMap elevated(f.level());
    const std::span<const float> x = turned.coefficients();
    const CsrMatrix& a = matrices_[static_cast<std::size_t>(k)];
    const CsrMatrix* b = t == 0.0 ? nullptr : &matrices_[static_cast<std::size_t>(k) + 1];
    for (std::size_t row = 0; row < elevated.coefficientCount(); ++row) {
      double lower = 0.0;
      for (std::uint32_t e = a.rowStart[row]; e < a.rowStart[row + 1]; ++e)
        lower += double{a.value[e]} * x[a.column[e]];
      if (b == nullptr) {
        elevated[row] = static_cast<float>(lower);
        continue;
      }
      double upper = 0.0;
      for (std::uint32_t e = b->rowStart[row]; e < b->rowStart[row + 1]; ++e)
        upper += double{b->value[e]} * x[b->column[e]];
      elevated[row] = static_cast<float>((1.0 - t) * lower + t * upper);
    }
    out = shiftPhi(elevated, alpha);
  }

  std::vector<SparseMatrixView> views() const {
    std::vector<SparseMatrixView> out;
    out.reserve(matrices_.size());
    for (const CsrMatrix& a : matrices_) out.push_back({a.rowStart, a.column, a.value});
    return out;
  }

  std::size_t storedBytes() const override { return coefficientBytes(slices_) + sharedBytes(); }

  std::size_t sharedBytes() const override {
    std::size_t bytes = 0;
    for (const CsrMatrix& a : matrices_) bytes += a.bytes();
    return bytes;
  }

 private:
  std::vector<HaarMap> slices_;
  std::shared_ptr<const std::vector<CsrMatrix>> shared_;
  const std::vector<CsrMatrix>& matrices_;  // matrices_[k]: elevate_{β_k}, β_k = kπ/(K−1)
};

}  // namespace

std::unique_ptr<SliceRotator> makeMatrixRotator(std::vector<HaarMap> slices, const RotatorOptions& options) {
  checkSlices(slices, "matrix rotator");
  if (options.matrixElevations < 2) {
    throw std::invalid_argument("matrix rotator: matrixElevations must be at least 2 (β = 0 and π), got " +
                                std::to_string(options.matrixElevations));
  }
  if (!(options.matrixThreshold >= 0.0 && options.matrixThreshold < 1.0)) {
    throw std::invalid_argument("matrix rotator: matrixThreshold must lie in [0, 1), got " +
                                std::to_string(options.matrixThreshold));
  }
  const int level = slices.front().level();
  const double estimate = options.matrixElevations * static_cast<double>(mapSize(level)) * mapSize(level) *
                          kEntriesPerColumn * (sizeof(std::uint32_t) + sizeof(float));
  if (estimate > kMaxMatrixBytes) {
    throw std::invalid_argument("matrix rotator: " + std::to_string(options.matrixElevations) +
                                " elevation matrices at level " + std::to_string(level) + " would hold about " +
                                std::to_string(static_cast<long long>(estimate / (1024 * 1024))) +
                                " MiB (about 50 entries of 8 bytes per column), over the " +
                                std::to_string(static_cast<long long>(kMaxMatrixBytes / (1024 * 1024))) +
                                " MiB budget; use a lower level or fewer elevations");
  }
  return std::make_unique<MatrixRotator>(std::move(slices), options);
}

}  // namespace haarcast::detail

namespace haarcast {

std::vector<SparseMatrixView> elevationMatrixViews(const SliceRotator& r) {
  const auto* matrix = dynamic_cast<const detail::MatrixRotator*>(&r);
  if (matrix == nullptr) {
    throw std::invalid_argument("elevationMatrixViews: the rotator's method is " +
                                std::string(methodName(r.method())) + ", not matrix");
  }
  return matrix->views();
}

}  // namespace haarcast
