// The seed's Haar-domain rotation; see rotate_haar.h for the method and the
// two variants. Notation: the rotation works on a "working" map of level
// w = start + 1 (side mw, pixel steps dθ = π/mw, dφ = 2π/mw). Difference
// fields of g on that grid:
//   dTheta(t, c) = g(t+1, c) − g(t, c)        t ∈ [0, mw−1), c ∈ [0, mw)
//   dPhi(r, u)   = g(r, u+1) − g(r, u)        r ∈ [0, mw),  u ∈ [0, mw−1)
//   dMixed(t, u) = second difference at the corner between four pixels.
#include "haarcast/core/rotate_haar.h"

#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>

#include "rotators.h"

namespace haarcast {
namespace {

// A row-major 2D array of doubles.
struct Grid {
  int rows = 0;
  int cols = 0;
  std::vector<double> v;
  Grid(int r, int c) : rows(r), cols(c), v(static_cast<std::size_t>(r) * static_cast<std::size_t>(c), 0.0) {}
  double& operator()(int r, int c) { return v[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + c]; }
  double operator()(int r, int c) const {
    return v[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + c];
  }
};

// Samples a field stored on a regular (θ, φ) lattice θ_r = theta0 + r·step_θ,
// φ_c = phi0 + c·step_φ: bilinear, φ periodic over `cols` samples, θ clamped
// to the lattice.
struct Lattice {
  const Grid* grid;
  double theta0, thetaStep, phi0, phiStep;

  double operator()(double theta, double phi) const {
    const Grid& g = *grid;
    double y = (theta - theta0) / thetaStep;
    y = std::clamp(y, 0.0, static_cast<double>(g.rows - 1));
    const double x = (phi - phi0) / phiStep;
    const double fy = std::floor(y), fx = std::floor(x);
    const double ty = y - fy, tx = x - fx;
    const int r0 = static_cast<int>(fy);
    const int r1 = std::min(r0 + 1, g.rows - 1);
    const int cw = static_cast<int>(fx);
    const int c0 = ((cw % g.cols) + g.cols) % g.cols;
    const int c1 = (c0 + 1) % g.cols;
    const double top = (1 - tx) * g(r0, c0) + tx * g(r0, c1);
    const double bottom = (1 - tx) * g(r1, c0) + tx * g(r1, c1);
    return (1 - ty) * top + ty * bottom;
  }
};

// ---- Source mapping and its Jacobian (seed eqs. 8–9) -----------------------

struct SourcePoint {
  double theta, phi;          // Θ, Φ
  double dThetaDt, dThetaDp;  // ∂Θ/∂θ, ∂Θ/∂φ
  double dPhiDt, dPhiDp;      // ∂Φ/∂θ, ∂Φ/∂φ
};

// Θ = acos(s_y), Φ = atan2(s_x, s_z) with s = Rᵀ p(θ, φ); the Jacobian from
// s_θ = Rᵀ p_θ and s_φ = Rᵀ p_φ.
SourcePoint sourceWithJacobian(const glm::dmat3& rt, double theta, double phi) {
  const double st = std::sin(theta), ct = std::cos(theta), sp = std::sin(phi), cp = std::cos(phi);
  const glm::dvec3 s = rt * glm::dvec3(st * sp, ct, st * cp);
  const glm::dvec3 sT = rt * glm::dvec3(ct * sp, -st, ct * cp);
  const glm::dvec3 sP = rt * glm::dvec3(st * cp, 0.0, -st * sp);
  SourcePoint q{};
  const Spherical sph = directionToSpherical(s);
  q.theta = sph.theta;
  q.phi = sph.phi;
  const double rho2 = std::max(s.x * s.x + s.z * s.z, 1e-24);
  const double rho = std::sqrt(rho2);
  q.dThetaDt = -sT.y / rho;
  q.dThetaDp = -sP.y / rho;
  q.dPhiDt = (s.z * sT.x - s.x * sT.z) / rho2;
  q.dPhiDp = (s.z * sP.x - s.x * sP.z) / rho2;
  return q;
}

// ---- Difference fields of g -------------------------------------------------

struct DifferenceFields {
  Grid dTheta, dPhi, dMixed;
  std::optional<double> workingScaling;  // when absolute values were known (refined)
  explicit DifferenceFields(int mw) : dTheta(mw - 1, mw), dPhi(mw, mw - 1), dMixed(mw - 1, mw - 1) {}

  // The diagonal band from the θ-difference of the φ-differences (the seed's
  // "cross-derivative of the horizontal coefficients"): h, v and d' then
  // describe one map.
  void deriveMixed() {
    for (int t = 0; t + 1 < dPhi.rows; ++t)
      for (int u = 0; u < dPhi.cols; ++u) dMixed(t, u) = dPhi(t + 1, u) - dPhi(t, u);
  }
};

// The start level's details, as a working map of side mw (details divided by
// the 2^(n−w) that separates a level-n map from its level-w version).
struct StartDetails {
  int mw;
  Grid h, v, d;  // (mw/2)²
  StartDetails(const HaarMap& f, int start) : mw(2 << start), h(mw / 2, mw / 2), v(mw / 2, mw / 2), d(mw / 2, mw / 2) {
    const double scale = 1.0 / static_cast<double>(1 << (f.level() - (start + 1)));
    for (int i = 0; i < mw / 2; ++i) {
      for (int j = 0; j < mw / 2; ++j) {
        h(i, j) = f.detail(Band::Horizontal, start, i, j) * scale;
        v(i, j) = f.detail(Band::Vertical, start, i, j) * scale;
        d(i, j) = f.detail(Band::Diagonal, start, i, j) * scale;
      }
    }
  }
};

// Faithful: details as derivative samples at block centres, Jacobian chain
// rule at each pixel boundary (seed eqs. 11–12).
DifferenceFields faithfulDifferences(const StartDetails& s, const glm::dmat3& rt) {
  const int mw = s.mw, half = mw / 2;
  const double dT = kPi / mw, dP = kTwoPi / mw;
  Grid fT(half, half), fP(half, half);
  for (int i = 0; i < half; ++i) {
    for (int j = 0; j < half; ++j) {
      fT(i, j) = -s.v(i, j) / dT;
      fP(i, j) = -s.h(i, j) / dP;
    }
  }
  // Block centres sit at θ = (2i+1)dθ, φ = (2j+1)dφ.
  const Lattice lT{&fT, dT, 2 * dT, dP, 2 * dP}, lP{&fP, dT, 2 * dT, dP, 2 * dP};

  DifferenceFields out(mw);
  for (int t = 0; t + 1 < mw; ++t) {
    for (int c = 0; c < mw; ++c) {  // boundary between rows t, t+1 at column c's centre
      const SourcePoint q = sourceWithJacobian(rt, (t + 1) * dT, (c + 0.5) * dP);
      out.dTheta(t, c) = dT * (lT(q.theta, q.phi) * q.dThetaDt + lP(q.theta, q.phi) * q.dPhiDt);  // eq. 11
    }
  }
  for (int r = 0; r < mw; ++r) {
    for (int u = 0; u + 1 < mw; ++u) {
      const SourcePoint q = sourceWithJacobian(rt, (r + 0.5) * dT, (u + 1) * dP);
      out.dPhi(r, u) = dP * (lT(q.theta, q.phi) * q.dThetaDp + lP(q.theta, q.phi) * q.dPhiDp);  // eq. 12
    }
  }
  out.deriveMixed();
  return out;
}

// f's differences on the working grid: dT(t, c) = f(t+1, c) − f(t, c),
// dP(r, c) = f(r, c+1) − f(r, c) with c+1 wrapping; and, where the variant
// knows them, absolute values of f (for the scaling coefficient's anchor).
struct SourceDifferences {
  Grid dT, dP;
  std::function<double(int, int)> pixel;  // empty when only differences are known
  explicit SourceDifferences(int mw) : dT(mw - 1, mw), dP(mw, mw) {}
};

// Inside each 2×2 block the details give both columns' θ-differences and
// both rows' φ-differences exactly: with corners a b / c d,
// c − a = −v − d', d − b = −v + d', b − a = −h − d', d − c = −h + d'.
void withinBlockDifferences(const StartDetails& s, SourceDifferences& out) {
  for (int i = 0; i < s.mw / 2; ++i)
    for (int j = 0; j < s.mw / 2; ++j) {
      out.dT(2 * i, 2 * j) = -s.v(i, j) - s.d(i, j);
      out.dT(2 * i, 2 * j + 1) = -s.v(i, j) + s.d(i, j);
      out.dP(2 * i, 2 * j) = -s.h(i, j) - s.d(i, j);
      out.dP(2 * i + 1, 2 * j) = -s.h(i, j) + s.d(i, j);
    }
}

// Across a block boundary the pixel difference is the difference of the two
// blocks' scaling values plus terms in their details: for the boundary below
// block (i, j) in its column half σ (+1 left, −1 right),
//   [(s' − s) + σ(h' − h) + (v' + v) + σ(d' + d)] / 2,
// and for the boundary right of block (i, j) in its row half σ (+1 top),
//   [(s' − s) + (h' + h) + σ(v' − v) + σ(d' + d)] / 2.
// `sDiffTheta(i, j)` = s(i+1, j) − s(i, j); `sDiffPhi(i, j)` = s(i, j+1) − s(i, j).
template <typename SDiffTheta, typename SDiffPhi>
void acrossBlockDifferences(const StartDetails& s, SDiffTheta sDiffTheta, SDiffPhi sDiffPhi, SourceDifferences& out) {
  const int half = s.mw / 2;
  for (int i = 0; i + 1 < half; ++i)
    for (int j = 0; j < half; ++j) {
      const double ds = sDiffTheta(i, j);
      for (int dj = 0; dj < 2; ++dj) {
        const double sg = dj ? -1.0 : 1.0;
        out.dT(2 * i + 1, 2 * j + dj) = 0.5 * (ds + sg * (s.h(i + 1, j) - s.h(i, j)) + (s.v(i + 1, j) + s.v(i, j)) +
                                               sg * (s.d(i + 1, j) + s.d(i, j)));
      }
    }
  for (int i = 0; i < half; ++i)
    for (int j = 0; j < half; ++j) {
      const int jn = (j + 1) % half;
      const double ds = sDiffPhi(i, j);
      for (int di = 0; di < 2; ++di) {
        const double sg = di ? -1.0 : 1.0;
        out.dP(2 * i + di, 2 * j + 1) =
            0.5 * (ds + (s.h(i, jn) + s.h(i, j)) + sg * (s.v(i, jn) - s.v(i, j)) + sg * (s.d(i, jn) + s.d(i, j)));
      }
    }
}

// Refined: the start level's scaling values come from all coarser levels, so
// every difference is exact and absolute values are known.
SourceDifferences exactDifferences(const HaarMap& f, const StartDetails& s, int start) {
  const int half = s.mw / 2;
  const double scale = 1.0 / static_cast<double>(1 << (f.level() - (start + 1)));
  auto sv = std::make_shared<std::vector<double>>(scalingValues(f, start));
  for (double& x : *sv) x *= scale;
  auto sAt = [sv, half](int i, int j) { return (*sv)[static_cast<std::size_t>(i) * static_cast<std::size_t>(half) + j]; };
  SourceDifferences out(s.mw);
  withinBlockDifferences(s, out);
  acrossBlockDifferences(
      s, [&](int i, int j) { return sAt(i + 1, j) - sAt(i, j); },
      [&](int i, int j) { return sAt(i, (j + 1) % half) - sAt(i, j); }, out);
  // Pixel (row, col) of block (i, j): a, b, c, d = (s ± h ± v ± d')/2.
  out.pixel = [sAt, &s](int row, int col) {
    const int i = row / 2, j = col / 2;
    const double sh = col % 2 ? -1.0 : 1.0, svv = row % 2 ? -1.0 : 1.0;
    return 0.5 * (sAt(i, j) + sh * s.h(i, j) + svv * s.v(i, j) + sh * svv * s.d(i, j));
  };
  return out;
}

// Local: only the start level and the one above it. Sibling blocks' scaling
// differences follow from their parent's details (s_TL = (S+h+v+d)/2, …);
// across parents they are estimated by the central difference of the two
// neighbouring sibling differences. No absolute value is known.
SourceDifferences localDifferences(const HaarMap& f, const StartDetails& s, int start) {
  const int half = s.mw / 2;
  const double scale = 1.0 / static_cast<double>(1 << (f.level() - (start + 1)));
  auto parent = [&](Band b, int i, int j) { return f.detail(b, start - 1, i / 2, j / 2) * scale; };
  // Within one parent: s(2I+1, ·) − s(2I, ·) and s(·, 2J+1) − s(·, 2J).
  auto siblingTheta = [&](int i, int j) {
    const double v = parent(Band::Vertical, i, j), d = parent(Band::Diagonal, i, j);
    return j % 2 ? -v + d : -v - d;
  };
  auto siblingPhi = [&](int i, int j) {
    const double h = parent(Band::Horizontal, i, j), d = parent(Band::Diagonal, i, j);
    return i % 2 ? -h + d : -h - d;
  };
  auto sDiffTheta = [&](int i, int j) {
    if (i % 2 == 0) return siblingTheta(i, j);
    const double before = siblingTheta(i - 1, j);
    return i + 2 < half ? 0.5 * (before + siblingTheta(i + 1, j)) : before;
  };
  auto sDiffPhi = [&](int i, int j) {
    if (half == 1) return 0.0;  // one block: the wrap joins it to itself
    if (j % 2 == 0) return siblingPhi(i, j);
    return 0.5 * (siblingPhi(i, j - 1) + siblingPhi(i, (j + 1) % half));
  };
  SourceDifferences out(s.mw);
  withinBlockDifferences(s, out);
  acrossBlockDifferences(s, sDiffTheta, sDiffPhi, out);
  return out;
}

// g's differences by the finite chain rule over f's differences (shared by
// refined and local).
DifferenceFields finiteChainRule(const SourceDifferences& fd, int mw, const glm::dmat3& rt) {
  const double dT = kPi / mw, dP = kTwoPi / mw;
  const Grid& fT = fd.dT;
  const Grid& fP = fd.dP;

  // Source position of every pixel centre of g, in f's pixel coordinates
  // (x along φ, y along θ; pixel centres at integers).
  struct Point { double x, y; };
  std::vector<Point> src(static_cast<std::size_t>(mw) * static_cast<std::size_t>(mw));
  for (int r = 0; r < mw; ++r)
    for (int c = 0; c < mw; ++c) {
      const Spherical q = directionToSpherical(rt * sphericalToDirection((r + 0.5) * dT, (c + 0.5) * dP));
      src[static_cast<std::size_t>(r) * mw + c] = {q.phi / dP - 0.5, q.theta / dT - 0.5};
    }
  auto at = [&](int r, int c) { return src[static_cast<std::size_t>(r) * mw + c]; };

  // f(S(p₂)) − f(S(p₁)), the chain rule in finite form. Between four pixel
  // centres f is bilinear, f = f₀ + y·dθ + x·dφ + xy·(dφ' − dφ) (dφ' the row
  // below), so along the straight path in (x, y) — x the short way round —
  // the difference is a sum over the cells crossed of terms in the
  // difference fields alone: exact for the bilinear model that `spatial`
  // resamples with. Beyond the first and last row centres θ is clamped
  // (sphere_map.h), so there only dφ of the polar row acts.
  auto difference = [&](Point a, Point b) {
    double dx = b.x - a.x;
    dx -= std::round(dx / mw) * mw;
    const double dy = b.y - a.y;
    // Walk the path s ∈ [0, 1], stopping where x or y crosses an integer
    // line. Each axis's crossings are evenly spaced in s, so the two streams
    // merge without sorting or storage — a path near a source pole may cross
    // half the map's columns.
    constexpr double kNever = 2.0;
    auto firstCrossing = [](double p0, double dp) {
      if (dp > 0.0) return (std::floor(p0) + 1.0 - p0) / dp;
      if (dp < 0.0) return (std::ceil(p0) - 1.0 - p0) / dp;
      return kNever;
    };
    double nextX = firstCrossing(a.x, dx), nextY = firstCrossing(a.y, dy);
    const double stepX = dx != 0.0 ? 1.0 / std::abs(dx) : 0.0, stepY = dy != 0.0 ? 1.0 / std::abs(dy) : 0.0;
    double sum = 0.0, s0 = 0.0;
    while (s0 < 1.0) {
      const double s1 = std::min({nextX, nextY, 1.0});
      if (s1 > s0) {
        const double sm = 0.5 * (s0 + s1);
        const double cx = std::floor(a.x + sm * dx), cy = std::floor(a.y + sm * dy);
        const int col = ((static_cast<int>(cx) % mw) + mw) % mw;
        const int row = static_cast<int>(cy);
        const double x0 = a.x + s0 * dx - cx, x1 = a.x + s1 * dx - cx;
        if (row < 0 || row >= mw - 1) {
          sum += (x1 - x0) * fP(row < 0 ? 0 : mw - 1, col);
        } else {
          const double y0 = a.y + s0 * dy - cy, y1 = a.y + s1 * dy - cy;
          const double mixed = fP(row + 1, col) - fP(row, col);
          sum += (y1 - y0) * fT(row, col) + (x1 - x0) * fP(row, col) + (x1 * y1 - x0 * y0) * mixed;
        }
      }
      if (nextX <= s1) nextX += stepX;
      if (nextY <= s1) nextY += stepY;
      s0 = s1;
    }
    return sum;
  };

  DifferenceFields out(mw);
  for (int t = 0; t + 1 < mw; ++t)
    for (int c = 0; c < mw; ++c) out.dTheta(t, c) = difference(at(t, c), at(t + 1, c));
  for (int r = 0; r < mw; ++r)
    for (int u = 0; u + 1 < mw; ++u) out.dPhi(r, u) = difference(at(r, u), at(r, u + 1));
  out.deriveMixed();

  // The scaling coefficient is the one number differences cannot give. With
  // absolute values known, anchor it on f at the source of g's first pixel
  // (bilinear, as everywhere) and sum the differences out to every pixel.
  if (!fd.pixel) return out;
  const Point p0 = at(0, 0);
  const double y0 = std::clamp(p0.y, 0.0, static_cast<double>(mw - 1));
  const int r0 = std::min(static_cast<int>(y0), mw - 2);
  const int c0 = ((static_cast<int>(std::floor(p0.x)) % mw) + mw) % mw;
  const double tx = p0.x - std::floor(p0.x), ty = y0 - r0;
  const double anchor = fd.pixel(r0, c0) + ty * fT(r0, c0) + tx * fP(r0, c0) + tx * ty * (fP(r0 + 1, c0) - fP(r0, c0));
  double total = 0.0, rowStart = anchor;
  for (int r = 0; r < mw; ++r) {
    if (r > 0) rowStart += out.dTheta(r - 1, 0);
    double value = rowStart;
    for (int c = 0; c < mw; ++c) {
      if (c > 0) value += out.dPhi(r, c - 1);
      total += value;
    }
  }
  out.workingScaling = total / mw;
  return out;
}

// ---- From differences to details: seed eqs. 14–16, recursively -------------

// For a field F with rows along the triangle axis (mw−1 boundaries) and
// columns along the box axis (mw pixels), emits for every detail level l and
// block (a, b) — a along the triangle axis — the sum Σ tri(t)·F(t, c) over the
// block (the seed's h_t ⊗ h_s before normalisation). The triangle of the next
// coarser level is this one convolved with [1 2 1] upsampled by the current
// half-width K (seed: h_{t,j−l} = h_{t,j} ∗ h^l_{t,j}); the box doubles.
template <typename Emit>
void triangleBoxSums(const Grid& field, int mw, int finest, Emit emit) {
  // T(a, b): rows a·K for a ∈ [0, mw/K − 1), columns = blocks of 2K pixels.
  Grid t(mw - 1, mw / 2);
  for (int a = 0; a + 1 < mw; ++a)
    for (int b = 0; b < mw / 2; ++b) t(a, b) = field(a, 2 * b) + field(a, 2 * b + 1);
  for (int l = finest;; --l) {
    const int blocks = 1 << l;
    for (int a = 0; a < blocks; ++a)
      for (int b = 0; b < blocks; ++b) emit(l, a, b, t(2 * a, b));
    if (l == 0) break;
    Grid next(blocks - 1, blocks / 2);
    for (int a = 0; a + 1 < blocks; ++a)
      for (int b = 0; b < blocks / 2; ++b)
        for (int q = 0; q < 2; ++q)
          next(a, b) += t(2 * a, 2 * b + q) + 2.0 * t(2 * a + 1, 2 * b + q) + t(2 * a + 2, 2 * b + q);
    t = std::move(next);
  }
}

// Triangle kernels along both axes (the diagonal band).
template <typename Emit>
void triangleTriangleSums(const Grid& field, int finest, Emit emit) {
  Grid q = field;  // (mw−1)²
  for (int l = finest;; --l) {
    const int blocks = 1 << l;
    for (int a = 0; a < blocks; ++a)
      for (int b = 0; b < blocks; ++b) emit(l, a, b, q(2 * a, 2 * b));
    if (l == 0) break;
    static constexpr double w[3] = {1.0, 2.0, 1.0};
    Grid next(blocks - 1, blocks - 1);
    for (int a = 0; a + 1 < blocks; ++a)
      for (int b = 0; b + 1 < blocks; ++b) {
        double sum = 0.0;
        for (int p = 0; p < 3; ++p)
          for (int r = 0; r < 3; ++r) sum += w[p] * w[r] * q(2 * a + p, 2 * b + r);
        next(a, b) = sum;
      }
    q = std::move(next);
  }
}

Grid transpose(const Grid& g) {
  Grid t(g.cols, g.rows);
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) t(c, r) = g(r, c);
  return t;
}

// ⟨ψ, ΔΩ⟩ of the vertical detail of level l, block row i, in a level-n map:
// Σ solid angle of its top-half rows − Σ of its bottom-half rows (per column).
double verticalMoment(int n, int l, int i) {
  const int side = 1 << (n - l);
  const int m = mapSize(n);
  const double step = kPi / m;
  const int r0 = i * side, rMid = r0 + side / 2, r1 = r0 + side;
  // Σ_rows (cos θ⁻ − cos θ⁺)·2π/M telescopes.
  auto band = [&](int a, int b) { return (std::cos(a * step) - std::cos(b * step)) * kTwoPi / m; };
  return band(r0, rMid) - band(rMid, r1);
}

}  // namespace

double integralFromCoefficients(const HaarMap& f) {
  const int n = f.level();
  double sum = f.scaling() * (4.0 * kPi / f.size());
  for (int l = 0; l < n; ++l)
    for (int i = 0; i < (1 << l); ++i) {
      const double w = verticalMoment(n, l, i);
      for (int j = 0; j < (1 << l); ++j) sum += f.detail(Band::Vertical, l, i, j) * w;
    }
  return sum;
}

double verticalDetailMoment(int mapLevel, int l, int i) { return verticalMoment(mapLevel, l, i); }

PixelDifferences refinedPixelDifferences(const HaarMap& f) {
  const int n = f.level();
  if (n < 1) throw std::invalid_argument("refinedPixelDifferences: a level-0 map has no pixel boundaries");
  const StartDetails details(f, n - 1);
  const SourceDifferences d = exactDifferences(f, details, n - 1);
  return {details.mw, d.dT.v, d.dP.v};
}

HaarMap rotateHaar(const HaarMap& f, const EulerYXY& r, const HaarRotationOptions& options) {
  const int n = f.level();
  if (n < 1) return f;  // a 1×1 map is a constant: every rotation leaves it.
  const int start = options.startLevel < 0 ? n - 1 : options.startLevel;
  if (start > n - 1) {
    throw std::invalid_argument("rotateHaar: start level " + std::to_string(start) + " is finer than the map's finest detail level " +
                                std::to_string(n - 1));
  }
  const glm::dmat3 rt = glm::transpose(rotationMatrix(r));
  const StartDetails details(f, start);
  DifferenceFields g(details.mw);
  switch (options.variant) {
    case HaarVariant::Faithful: g = faithfulDifferences(details, rt); break;
    case HaarVariant::Local: g = finiteChainRule(localDifferences(f, details, start), details.mw, rt); break;
    case HaarVariant::Refined: g = finiteChainRule(exactDifferences(f, details, start), details.mw, rt); break;
  }

  // Details of g: v = −Σ/side, h = −Σ/side, d' = Σ/side, side in working
  // pixels; × 2^(n−w) back to the level-n normalisation.
  HaarMap out(n);
  const double up = static_cast<double>(1 << (n - (start + 1)));
  const int mw = details.mw;
  auto sideOf = [&](int l) { return static_cast<double>(mw >> l); };
  triangleBoxSums(g.dTheta, mw, start, [&](int l, int a, int b, double sum) {
    out.detail(Band::Vertical, l, a, b) = static_cast<float>(-sum / sideOf(l) * up);
  });
  triangleBoxSums(transpose(g.dPhi), mw, start, [&](int l, int a, int b, double sum) {
    out.detail(Band::Horizontal, l, b, a) = static_cast<float>(-sum / sideOf(l) * up);
  });
  triangleTriangleSums(g.dMixed, start, [&](int l, int a, int b, double sum) {
    out.detail(Band::Diagonal, l, a, b) = static_cast<float>(sum / sideOf(l) * up);
  });

  if (g.workingScaling) {
    out.scaling() = static_cast<float>(*g.workingScaling * up);
  } else {
    // No absolute value to anchor on: take the scaling coefficient from the
    // rotation-invariant integral.
    double rest = 0.0;
    for (int l = 0; l <= start; ++l)
      for (int i = 0; i < (1 << l); ++i) {
        const double w = verticalMoment(n, l, i);
        for (int j = 0; j < (1 << l); ++j) rest += out.detail(Band::Vertical, l, i, j) * w;
      }
    out.scaling() = static_cast<float>((integralFromCoefficients(f) - rest) / (4.0 * kPi / f.size()));
  }
  return out;
}

namespace detail {
namespace {
class HaarRotator final : public SliceRotator {
 public:
  HaarRotator(std::vector<HaarMap> slices, const RotatorOptions& o)
      : slices_(std::move(slices)), options_{o.haarVariant, o.haarStartLevel} {
    const int n = slices_.front().level();
    if (options_.startLevel > n - 1) {
      throw std::invalid_argument("haar rotator: start level " + std::to_string(options_.startLevel) +
                                  " is finer than the slices' finest detail level " + std::to_string(n - 1));
    }
  }
  RotationMethod method() const override { return RotationMethod::Haar; }
  std::size_t sliceCount() const override { return slices_.size(); }
  int level() const override { return slices_.front().level(); }
  void rotate(std::size_t slice, const EulerYXY& r, HaarMap& out) const override {
    out = rotateHaar(slices_.at(slice), r, options_);
  }
  // Only the unrotated slices: the point of the method.
  std::size_t storedBytes() const override { return coefficientBytes(slices_); }

 private:
  std::vector<HaarMap> slices_;
  HaarRotationOptions options_;
};
}  // namespace

std::unique_ptr<SliceRotator> makeHaarRotator(std::vector<HaarMap> slices, const RotatorOptions& options) {
  return std::make_unique<HaarRotator>(std::move(slices), options);
}
}  // namespace detail

}  // namespace haarcast
