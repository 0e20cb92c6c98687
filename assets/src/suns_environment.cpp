// The "suns" environment (suns_environment.h). Energies, by the unit
// tests' quadratures: ∫L dω ≈ (6.31, 6.20, 6.34); on an upward surface the
// irradiance is ≈ (3.10, 3.05, 3.13), of which the suns carry 85 %, 81 %
// and 72 % (the blue zenith takes the rest of the blue).
#include "haarcast/assets/suns_environment.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

namespace haarcast::assets {
namespace {

constexpr double kDegree = kPi / 180.0;

// Three suns: high, middle and low, away from each other in azimuth so that
// an object casts three distinct shadows; each gives an upward surface
// about a third to a half of the suns' irradiance.
constexpr Sun kSuns[] = {
    {60.0, 40.0, 2.0, {760.0, 715.0, 640.0}},   // high, warm white
    {35.0, 160.0, 2.5, {390.0, 390.0, 395.0}},  // middle, white
    {20.0, 280.0, 1.5, {990.0, 810.0, 630.0}},  // low, orange
};
constexpr glm::dvec3 kZenith{0.10, 0.15, 0.28};
constexpr glm::dvec3 kHorizon{0.24, 0.25, 0.27};
constexpr glm::dvec3 kNadir{0.08, 0.075, 0.07};

// Cells per side of each sun's quadrature box (see the file comment of
// the header): a cell is 2ρ/512 ≤ 0.01° wide, far under any map pixel.
constexpr int kSunCells = 512;

struct SunFrame {
  glm::dvec3 centre;
  double theta, phi, radius, cosRadius;
  glm::dvec3 radiance;
};

const std::array<SunFrame, std::size(kSuns)>& frames() {
  static const auto f = [] {
    std::array<SunFrame, std::size(kSuns)> out{};
    for (std::size_t k = 0; k < std::size(kSuns); ++k) {
      const Sun& s = kSuns[k];
      SunFrame& g = out[k];
      g.theta = (90.0 - s.elevationDeg) * kDegree;
      g.phi = s.azimuthDeg * kDegree;
      g.centre = sphericalToDirection(g.theta, g.phi);
      g.radius = s.radiusDeg * kDegree;
      g.cosRadius = std::cos(g.radius);
      g.radiance = s.radiance;
    }
    return out;
  }();
  return f;
}

glm::dvec3 sky(double y) {
  return y >= 0.0 ? kHorizon + (kZenith - kHorizon) * y : kHorizon + (kNadir - kHorizon) * (-y);
}

// ∫ sky(y) dy over [a, b], a ≤ b: the trapezoid rule is exact on each
// linear piece.
glm::dvec3 skyIntegral(double a, double b) {
  auto piece = [](double lo, double hi) { return (hi > lo) ? 0.5 * (hi - lo) * (sky(lo) + sky(hi)) : glm::dvec3(0.0); };
  return piece(a, std::min(b, 0.0)) + piece(std::max(a, 0.0), b);
}

glm::dvec3 sunsAt(const glm::dvec3& d) {
  glm::dvec3 out(0.0);
  for (const SunFrame& s : frames()) {
    const double c = d.x * s.centre.x + d.y * s.centre.y + d.z * s.centre.z;
    if (c > s.cosRadius) out += s.radiance * sunLimb(std::acos(std::min(c, 1.0)), s.radius);
  }
  return out;
}

}  // namespace

const SunsSky& sunsSky() {
  static const SunsSky s{kZenith, kHorizon, kNadir, std::span<const Sun>(kSuns)};
  return s;
}

double sunLimb(double angle, double radius) {
  const double t = std::clamp((radius - angle) / (0.5 * radius), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

glm::dvec3 sunsEnvironmentRadiance(const glm::dvec3& dir) { return sky(dir.y) + sunsAt(dir); }

std::array<SphereMap, 3> sunsEnvironment(int level) {
  checkLevel(level, "sunsEnvironment");
  const int m = mapSize(level);
  const double dPhi = kTwoPi / m;
  // The sky: its integral over each row, / the row's solid angle.
  std::array<SphereMap, 3> maps{SphereMap(level), SphereMap(level), SphereMap(level)};
  for (int r = 0; r < m; ++r) {
    const double y0 = std::cos((r + 1) * kPi / m), y1 = std::cos(r * kPi / m);
    const glm::dvec3 mean = skyIntegral(y0, y1) * dPhi / pixelSolidAngle(level, r);
    for (int c = 0; c < m; ++c)
      for (int ch = 0; ch < 3; ++ch) maps[static_cast<std::size_t>(ch)].at(r, c) = static_cast<float>(mean[ch]);
  }
  for (const SunFrame& s : frames()) {
    // The box [θs − ρ, θs + ρ] × [φs − Δφ, φs + Δφ], Δφ = asin(sin ρ / sin θs)
    // (the cap's widest azimuth; no sun is within ρ of a pole), a little
    // wider. Its cells' integrals add up per pixel over the rows it spans.
    const double margin = 1.01;
    const double yLo = std::cos(s.theta + margin * s.radius), yHi = std::cos(s.theta - margin * s.radius);
    const double halfPhi = margin * std::asin(std::sin(s.radius) / std::sin(s.theta));
    const double dy = (yHi - yLo) / kSunCells, dp = 2.0 * halfPhi / kSunCells;
    auto rowOf = [&](double y) { return std::min(static_cast<int>(std::acos(y) / kPi * m), m - 1); };
    const int rFirst = rowOf(yHi), rLast = rowOf(yLo);
    std::vector<glm::dvec3> sum(static_cast<std::size_t>(rLast - rFirst + 1) * static_cast<std::size_t>(m), glm::dvec3(0.0));
    for (int i = 0; i < kSunCells; ++i) {
      const double y = yLo + (i + 0.5) * dy;
      const double sinTheta = std::sqrt(std::max(0.0, 1.0 - y * y));
      const int r = rowOf(y);
      for (int j = 0; j < kSunCells; ++j) {
        double phi = s.phi - halfPhi + (j + 0.5) * dp;
        phi -= kTwoPi * std::floor(phi / kTwoPi);
        const glm::dvec3 d(sinTheta * std::sin(phi), y, sinTheta * std::cos(phi));
        const double cosAngle = d.x * s.centre.x + d.y * s.centre.y + d.z * s.centre.z;
        if (!(cosAngle > s.cosRadius)) continue;
        const int c = std::min(static_cast<int>(phi / kTwoPi * m), m - 1);
        sum[static_cast<std::size_t>(r - rFirst) * static_cast<std::size_t>(m) + static_cast<std::size_t>(c)] +=
            s.radiance * (sunLimb(std::acos(std::min(cosAngle, 1.0)), s.radius) * dy * dp);
      }
    }
    for (int r = rFirst; r <= rLast; ++r) {
      const double omega = pixelSolidAngle(level, r);
      for (int c = 0; c < m; ++c) {
        const glm::dvec3& v = sum[static_cast<std::size_t>(r - rFirst) * static_cast<std::size_t>(m) + static_cast<std::size_t>(c)];
        for (int ch = 0; ch < 3; ++ch) {
          if (v[ch] != 0.0) maps[static_cast<std::size_t>(ch)].at(r, c) += static_cast<float>(v[ch] / omega);
        }
      }
    }
  }
  return maps;
}

}  // namespace haarcast::assets
