// The built-in procedural HDR environment, in the world frame (+Y up, azimuth
// φ from +Z toward +X; DESIGN.md "Directions").
//
// Layers, back to front:
//   1. Sky above the horizon: kHorizonSky blended to kZenithSky by √cos θ
//      (the sky brightens quickly toward the horizon, as a clear sky does).
//   2. Ground below the horizon: kGroundNearHorizon blended to kGroundNadir by
//      √(−cos θ). The sky/ground step at the horizon is a hard edge.
//   3. Four rectangular windows (kWindows), each a flat rectangle facing the
//      origin, so its edges are great-circle arcs: inside if the gnomonic
//      projection onto the window's tangent plane lies within ±tan(half-angle).
//      A window replaces the background behind it.
//   4. The sun (kSun*), a disc of angular radius 3° added on top: a flat core
//      out to 1.5°, then a smoothstep fall-off to zero at 3°. Why soft: the
//      pixel means of a map are n×n-sample averages, and a hard-edged disc a
//      few samples wide is counted with lattice-point noise (±8% of the sun's
//      energy on a 128×128 sample grid, ±1% on 512×512); the soft edge cuts
//      that to ~5% and ~0.03%. The edge width (1.5°) is below the pixel size
//      of every level up to 6 (2.8°), so those maps hold the same frequencies
//      as with a hard disc.
//
// Energies (measured by the tests' quadrature): ∫L dω ≈ (58.3, 56.2, 54.3),
// of which the sun carries 85%, 82%, 75%, the windows 4–5%, sky and ground
// the rest. Peak radiance over mean radiance is about 2,150 (1,690 in a
// level-6 map, whose pixels average the sun's core with its edge).
#include "haarcast/assets/procedural_environment.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string>

#include "haarcast/core/brdf_slices.h"

namespace haarcast::assets {
namespace {

constexpr double kDegree = kPi / 180.0;

// Sky and ground radiance (linear RGB).
constexpr glm::dvec3 kZenithSky{0.45, 0.75, 1.6};
constexpr glm::dvec3 kHorizonSky{1.6, 1.7, 1.8};
constexpr glm::dvec3 kGroundNearHorizon{0.30, 0.26, 0.20};
constexpr glm::dvec3 kGroundNadir{0.12, 0.11, 0.10};

// The sun: elevation 35° above the horizon (θ = 55°), azimuth 60°.
constexpr double kSunElevationDeg = 35.0;
constexpr double kSunAzimuthDeg = 60.0;
constexpr double kSunRadiusDeg = 3.0;
constexpr double kSunLimbFraction = 0.5;  // outer part of the radius over which the disc fades out
constexpr glm::dvec3 kSunRadiance{10000.0, 9300.0, 8200.0};  // at the core; warm white

struct Window {
  double azimuthDeg;
  double elevationDeg;
  double halfWidthDeg;   // along the horizontal (increasing φ)
  double halfHeightDeg;  // along the window's up direction
  glm::dvec3 radiance;
};

// Varied azimuths and elevations, none within 30° of the sun.
constexpr Window kWindows[] = {
    {150.0, 10.0, 3.0, 5.0, {60.0, 58.0, 52.0}},  // a tall window near the horizon
    {235.0, 25.0, 4.0, 3.0, {30.0, 34.0, 40.0}},  // a wide, cool one
    {300.0, 50.0, 2.5, 2.5, {90.0, 90.0, 85.0}},  // a small, bright skylight
    {20.0, 70.0, 5.0, 2.0, {20.0, 20.0, 22.0}},   // a long, dim strip high up
};

double dot(const glm::dvec3& a, const glm::dvec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

glm::dvec3 fromElevationAzimuth(double elevationDeg, double azimuthDeg) {
  return sphericalToDirection((90.0 - elevationDeg) * kDegree, azimuthDeg * kDegree);
}

// A window's tangent frame: centre c, u horizontal toward increasing φ
// (+Y × c, normalised), v = c × u (toward the zenith).
struct WindowFrame {
  glm::dvec3 c, u, v;
  double tanHalfWidth, tanHalfHeight;
  glm::dvec3 radiance;
};

struct Scene {
  glm::dvec3 sun;
  double cosSunRadius;
  std::array<WindowFrame, std::size(kWindows)> windows;
};

const Scene& scene() {
  static const Scene s = [] {
    Scene out{};
    out.sun = fromElevationAzimuth(kSunElevationDeg, kSunAzimuthDeg);
    out.cosSunRadius = std::cos(kSunRadiusDeg * kDegree);
    for (std::size_t k = 0; k < std::size(kWindows); ++k) {
      const Window& w = kWindows[k];
      WindowFrame& f = out.windows[k];
      f.c = fromElevationAzimuth(w.elevationDeg, w.azimuthDeg);
      const double len = std::hypot(f.c.z, f.c.x);
      f.u = glm::dvec3(f.c.z / len, 0.0, -f.c.x / len);
      f.v = glm::dvec3(f.c.y * f.u.z - f.c.z * f.u.y,  // c × u
                       f.c.z * f.u.x - f.c.x * f.u.z,
                       f.c.x * f.u.y - f.c.y * f.u.x);
      f.tanHalfWidth = std::tan(w.halfWidthDeg * kDegree);
      f.tanHalfHeight = std::tan(w.halfHeightDeg * kDegree);
      f.radiance = w.radiance;
    }
    return out;
  }();
  return s;
}

glm::dvec3 mix(const glm::dvec3& a, const glm::dvec3& b, double t) { return a + (b - a) * t; }

}  // namespace

glm::dvec3 proceduralEnvironmentRadiance(const glm::dvec3& dir) {
  const Scene& s = scene();
  glm::dvec3 radiance = dir.y >= 0.0 ? mix(kHorizonSky, kZenithSky, std::sqrt(dir.y))
                                     : mix(kGroundNearHorizon, kGroundNadir, std::sqrt(-dir.y));
  for (const WindowFrame& w : s.windows) {
    const double d = dot(dir, w.c);
    // Gnomonic coordinates (dir·u, dir·v)/(dir·c) within the window's half-extents.
    if (d > 0.0 && std::abs(dot(dir, w.u)) <= w.tanHalfWidth * d &&
        std::abs(dot(dir, w.v)) <= w.tanHalfHeight * d) {
      radiance = w.radiance;
    }
  }
  const double cosSun = dot(dir, s.sun);
  if (cosSun > s.cosSunRadius) {
    // Smoothstep in angle from the edge (0) to the inner core (1).
    const double angle = std::acos(std::min(cosSun, 1.0));
    const double edge = kSunRadiusDeg * kDegree;
    const double t = std::clamp((edge - angle) / (kSunLimbFraction * edge), 0.0, 1.0);
    radiance += kSunRadiance * (t * t * (3.0 - 2.0 * t));
  }
  return radiance;
}

std::array<SphereMap, 3> proceduralEnvironment(int level, int supersampling) {
  checkLevel(level, "proceduralEnvironment");
  if (supersampling < 1 || supersampling > 64) {
    throw std::invalid_argument("proceduralEnvironment: supersampling " + std::to_string(supersampling) +
                                " is outside [1, 64]");
  }
  std::array<SphereMap, 3> maps;
  for (int c = 0; c < 3; ++c) {
    maps[static_cast<std::size_t>(c)] = supersampledMap(
        level, supersampling, [c](const glm::dvec3& dir) { return proceduralEnvironmentRadiance(dir)[c]; });
  }
  return maps;
}

}  // namespace haarcast::assets
