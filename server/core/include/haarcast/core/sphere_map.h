// Square longitude-latitude maps of spherical functions (DESIGN.md "Maps").
//
// A map of level n has M = 2^n rows and columns. Row i holds elevation
// θ_i = (i + ½)π/M measured from +Y, column j holds azimuth φ_j = (j + ½)2π/M
// measured from +Z toward +X. The direction of (θ, φ) is
// (sin θ sin φ, cos θ, sin θ cos φ) — the seed's equation for p.
//
// φ wraps around. θ is clamped at the poles: a sample above the first row's
// centre takes the first row's value (no reflection across the pole), which is
// what every resampler in haarcast does, so all rotation methods agree there.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "haarcast/core/shared_layout.h"

namespace haarcast {

using shared::kPi;  // shared_layout.h, where the shaders read it too
inline constexpr double kTwoPi = 2.0 * kPi;

// Largest map level the library accepts: level 12 is a 4096² map (64 MiB of
// floats); anything larger is a mistake in a request, not a real use.
inline constexpr int kMaxLevel = 12;

// Throws std::invalid_argument naming the bad level unless 0 <= level <= kMaxLevel.
void checkLevel(int level, const char* what);

inline int mapSize(int level) { return 1 << level; }

// Direction of spherical coordinates (θ, φ) in the haarcast convention.
inline glm::dvec3 sphericalToDirection(double theta, double phi) {
  const double s = std::sin(theta);
  return {s * std::sin(phi), std::cos(theta), s * std::cos(phi)};
}

struct Spherical {
  double theta;  // [0, π]
  double phi;    // [0, 2π)
};

// Inverse of sphericalToDirection for a unit (or any non-zero) vector.
Spherical directionToSpherical(const glm::dvec3& d);

inline double rowTheta(int level, int row) { return (row + 0.5) * kPi / mapSize(level); }
inline double colPhi(int level, int col) { return (col + 0.5) * kTwoPi / mapSize(level); }

// Exact solid angle of a pixel in row `row`: (cos θ⁻ − cos θ⁺)·2π/M.
double pixelSolidAngle(int level, int row);

// The four pixels and weights of bilinear interpolation at (θ, φ) on a map of
// `level`, between pixel centres: φ wraps, θ clamps at the poles (see the file
// comment). The one definition of the taps, used by SphereMap::sampleBilinear
// and by every resampler that needs its stencil explicitly (rotate_matrix).
struct BilinearTaps {
  std::array<int, 2> row;  // row[1] = row[0] + 1, or row[0] on the last row
  std::array<int, 2> col;  // col[1] = col[0] + 1 mod M
  double tRow;             // fraction from row[0] toward row[1], in [0, 1]
  double tCol;             // fraction from col[0] toward col[1], in [0, 1)
  // Weight of pixel (row[a], col[b]), a, b ∈ {0, 1}; the four sum to 1.
  double weight(int a, int b) const { return (a ? tRow : 1.0 - tRow) * (b ? tCol : 1.0 - tCol); }
};
BilinearTaps bilinearTaps(int level, double theta, double phi);

// A spherical function sampled at pixel centres, row-major (row = θ index).
class SphereMap {
 public:
  SphereMap() = default;
  explicit SphereMap(int level, float fill = 0.0f);

  // Samples f(direction) at every pixel centre.
  static SphereMap fromFunction(int level, const std::function<double(const glm::dvec3&)>& f);

  int level() const { return level_; }
  int size() const { return mapSize(level_); }
  std::size_t pixelCount() const { return values_.size(); }

  float& at(int row, int col) { return values_[index(row, col)]; }
  float at(int row, int col) const { return values_[index(row, col)]; }
  std::span<float> values() { return values_; }
  std::span<const float> values() const { return values_; }

  // ∫ f dω by the exact pixel solid angles.
  double integral() const;

  // Bilinear interpolation between pixel centres: φ wraps, θ clamps at the
  // poles (see the file comment). This is the one resampler of haarcast.
  double sampleBilinear(double theta, double phi) const;

  // Copy with every pixel multiplied by its solid angle: the form in which
  // the light enters the triple product (DESIGN.md "Solid angle").
  SphereMap weightedBySolidAngle() const;

  // The map at `coarser` ≤ level(): each pixel the solid-angle mean of the
  // 2^k × 2^k pixels it covers, so the integral is kept, and a map of area
  // means (Environment::maps) becomes the area means of the coarser level.
  // Throws std::invalid_argument for a finer or invalid level.
  SphereMap downsampled(int coarser) const;

 private:
  std::size_t index(int row, int col) const {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(size()) +
           static_cast<std::size_t>(col);
  }
  int level_ = 0;
  std::vector<float> values_{0.0f};
};

// The float lookup the device's passes make (shared::latLongTaps): the taps
// toward a direction of any length, and a map's value at them, bilinear,
// the columns blended first. One definition for the CPU's backdrop and its
// sky rays (render/renderer.h backdropRadiance, render/point_lights.cpp).
shared::LatLongTaps latLongTapsToward(int level, const glm::vec3& direction);
float valueAt(const SphereMap& map, const shared::LatLongTaps& taps);

}  // namespace haarcast
