// The "suns" environment: the radiance function is the model its parameters
// state, its integral (brute-force quadrature) equals the parameters'
// analytic integral, and the maps' integral equals both at every level, with
// each sun's energy in the pixels around it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

#include "haarcast/assets/suns_environment.h"

namespace haarcast::assets {
namespace {

constexpr double kDeg = kPi / 180.0;

glm::dvec3 sunDirection(const Sun& s) { return sphericalToDirection((90.0 - s.elevationDeg) * kDeg, s.azimuthDeg * kDeg); }

glm::dvec3 skyAt(double y) {
  const SunsSky& k = sunsSky();
  return y >= 0.0 ? k.horizon + (k.zenith - k.horizon) * y : k.horizon + (k.nadir - k.horizon) * (-y);
}

// ∫ limb(a) dω over a cap of radius ρ = 2π ∫₀^ρ limb(a) sin a da (midpoint, 1e5 steps).
double sunSolidAngle(double radius) {
  const int n = 100000;
  double sum = 0.0;
  for (int i = 0; i < n; ++i) {
    const double a = (i + 0.5) * radius / n;
    sum += sunLimb(a, radius) * std::sin(a);
  }
  return kTwoPi * sum * radius / n;
}

// From the parameters alone: ∫ sky dω = 2π ∫ sky(y) dy = π(2·horizon + zenith + nadir),
// plus each sun's radiance × its limb-weighted solid angle (no sun overlaps another).
glm::dvec3 analyticIntegral() {
  const SunsSky& k = sunsSky();
  glm::dvec3 total = kPi * (2.0 * k.horizon + k.zenith + k.nadir);
  for (const Sun& s : k.suns) total += s.radiance * sunSolidAngle(s.radiusDeg * kDeg);
  return total;
}

// ∫ f dω by the midpoint rule on an nu × 2nu grid in (cos θ, φ): equal areas.
glm::dvec3 quadrature(int nu, double u0, double u1, double phi0, double phi1) {
  glm::dvec3 sum(0.0);
  const int nphi = 2 * nu;
  const double du = (u1 - u0) / nu, dphi = (phi1 - phi0) / nphi;
  for (int i = 0; i < nu; ++i) {
    const double u = u0 + (i + 0.5) * du, s = std::sqrt(std::max(0.0, 1.0 - u * u));
    for (int j = 0; j < nphi; ++j) {
      const double phi = phi0 + (j + 0.5) * dphi;
      sum += sunsEnvironmentRadiance({s * std::sin(phi), u, s * std::cos(phi)});
    }
  }
  return sum * du * dphi;
}

TEST(SunsEnvironment, RadianceIsTheStatedModel) {
  for (const Sun& s : sunsSky().suns) {
    const glm::dvec3 c = sunDirection(s);
    const double rho = s.radiusDeg * kDeg;
    // Points at an angle a from the centre, towards the zenith side.
    const glm::dvec3 up = glm::dvec3(0, 1, 0) - c * c.y;
    const glm::dvec3 t = up / std::sqrt(up.x * up.x + up.y * up.y + up.z * up.z);
    auto at = [&](double a) { return c * std::cos(a) + t * std::sin(a); };
    for (double frac : {0.0, 0.4, 0.75, 0.9, 1.1}) {
      const glm::dvec3 d = at(frac * rho);
      const double w = frac <= 0.5 ? 1.0 : frac >= 1.0 ? 0.0 : frac == 0.75 ? 0.5 : sunLimb(frac * rho, rho);
      const glm::dvec3 expected = skyAt(d.y) + s.radiance * w;
      for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(sunsEnvironmentRadiance(d)[ch], expected[ch], 1e-9 * expected[ch]) << frac;
    }
  }
  // The sky alone: continuous at the horizon, the stated values at the poles.
  EXPECT_NEAR(sunsEnvironmentRadiance({0, 1, 0}).z, sunsSky().zenith.z, 1e-12);
  EXPECT_NEAR(sunsEnvironmentRadiance({0, -1, 0}).x, sunsSky().nadir.x, 1e-12);
  EXPECT_NEAR(sunsEnvironmentRadiance({0, 1e-9, -1}).y, sunsEnvironmentRadiance({0, -1e-9, -1}).y, 1e-8);
}

TEST(SunsEnvironment, RadianceIntegralMatchesTheParameters) {
  const glm::dvec3 analytic = analyticIntegral();
  const glm::dvec3 brute = quadrature(2048, -1.0, 1.0, 0.0, kTwoPi);
  std::cout << "∫L dω: analytic (" << analytic.x << ", " << analytic.y << ", " << analytic.z << "), quadrature ("
            << brute.x << ", " << brute.y << ", " << brute.z << ")\n";
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(brute[ch], analytic[ch], 1e-3 * analytic[ch]);
}

TEST(SunsEnvironment, MapIntegralsEqualTheRadianceIntegralAtEveryLevel) {
  const glm::dvec3 analytic = analyticIntegral();
  for (int level = 0; level <= 9; ++level) {
    SCOPED_TRACE(level);
    const auto maps = sunsEnvironment(level);
    for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(maps[static_cast<std::size_t>(ch)].integral(), analytic[ch], 2e-5 * analytic[ch]);
  }
}

TEST(SunsEnvironment, EachPixelNearASunHoldsItsAreaAverage) {
  // Level 5 pixels are 5.6° × 11.25°: a sun lies in one to four of them. The
  // 3×3 pixels around each sun against a brute-force average of each pixel.
  const int level = 5, m = mapSize(level);
  const auto maps = sunsEnvironment(level);
  for (const Sun& s : sunsSky().suns) {
    const Spherical sc = directionToSpherical(sunDirection(s));
    const int r0 = static_cast<int>(sc.theta / kPi * m), c0 = static_cast<int>(sc.phi / kTwoPi * m);
    double sunTotal = 0.0;
    for (int r = r0 - 1; r <= r0 + 1; ++r)
      for (int dc = -1; dc <= 1; ++dc) {
        const int c = (c0 + dc + m) % m;
        const double u1 = std::cos(r * kPi / m), u0 = std::cos((r + 1) * kPi / m);
        const double omega = pixelSolidAngle(level, r);
        const glm::dvec3 truth = quadrature(512, u0, u1, c * kTwoPi / m, (c + 1) * kTwoPi / m) / omega;
        sunTotal += truth.x * omega;
        // 0.2 % of the sun's whole energy spread over this pixel: the
        // quadratures' cells are ~0.01° on a sun of 1.5–2.5°.
        const double tolerance = 2e-3 * s.radiance.x * sunSolidAngle(s.radiusDeg * kDeg) / omega + 1e-4 * truth.x;
        EXPECT_NEAR(maps[0].at(r, c), truth.x, tolerance) << "sun at " << s.elevationDeg << "°, pixel " << r << ", " << c;
      }
    // The sun is there: its energy (and the sky's little) is in these pixels.
    EXPECT_GT(sunTotal, s.radiance.x * sunSolidAngle(s.radiusDeg * kDeg));
  }
}

TEST(SunsEnvironment, SunsCarryMostOfTheIrradianceOnAnUpwardSurface) {
  // E = ∫ L cos θ dω over the upper hemisphere: the sky analytically,
  // π·horizon + 2π/3·(zenith − horizon); each sun by quadrature in its cap.
  const SunsSky& k = sunsSky();
  const glm::dvec3 sky = kPi * k.horizon + (2.0 * kPi / 3.0) * (k.zenith - k.horizon);
  glm::dvec3 suns(0.0);
  for (const Sun& s : k.suns) {
    // cos θ varies by ±ρ·sin(elevation…) across the cap, linearly: its mean is the centre's.
    suns += s.radiance * (sunSolidAngle(s.radiusDeg * kDeg) * std::sin(s.elevationDeg * kDeg));
  }
  for (int ch = 0; ch < 3; ++ch) {
    const double share = suns[ch] / (suns[ch] + sky[ch]);
    std::cout << "channel " << ch << ": irradiance " << suns[ch] + sky[ch] << ", suns' share " << share << "\n";
    EXPECT_GT(share, 0.7);
    EXPECT_LT(share, 0.9);
  }
}

}  // namespace
}  // namespace haarcast::assets
