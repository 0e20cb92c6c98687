// The prefiltered light (prefiltered_light.h).
#include "haarcast/core/prefiltered_light.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "haarcast/core/check.h"
#include "haarcast/core/sphere_map.h"
#include <glm/geometric.hpp>

namespace haarcast {

namespace {
// Directions per texel of a cap mean; the golden angle turns each from the last.
constexpr int kCapSamples = 64;
const double kGoldenAngle = kPi * (3.0 - std::sqrt(5.0));
}  // namespace

PrefilteredLight PrefilteredLight::build(const std::array<SphereMap, 3>& maps) {
  const int finest = maps[0].level();
  if (finest < 0 || finest >= static_cast<int>(shared::kPrefilterLevels)) {
    throw std::invalid_argument("PrefilteredLight: level " + std::to_string(finest) + " is outside 0.." +
                                std::to_string(shared::kPrefilterLevels - 1));
  }
  for (const SphereMap& m : maps) {
    if (m.level() != finest) throw std::invalid_argument("PrefilteredLight: the channels' maps differ in level");
  }
  // The box pyramid: level l the solid-angle mean over each of its texels.
  PrefilteredLight box;
  box.finest_ = finest;
  box.texels_.assign(shared::prefilterOffset(static_cast<shared::uint>(finest + 1)), glm::vec4(0.0f));
  for (int l = 0; l <= finest; ++l) {
    const std::size_t base = shared::prefilterOffset(static_cast<shared::uint>(l));
    for (std::size_t c = 0; c < 3; ++c) {
      const SphereMap level = l == finest ? maps[c] : maps[c].downsampled(l);
      const std::span<const float> v = level.values();
      for (std::size_t k = 0; k < v.size(); ++k) box.texels_[base + k][static_cast<int>(c)] = v[k];
    }
  }
  // A box texel near a pole is a thin wedge, and the wedges around the pole
  // hold different means: a lookup there turns with the azimuth and shows
  // as a pinwheel on a mirror's reflection of the sky. Each coarser level
  // is therefore the mean over a spherical cap about the texel's centre of
  // the solid angle of the level's equatorial texel (2π²/M²), the same
  // whatever the direction, read from the box level two finer.
  PrefilteredLight out = box;
  for (int l = 1; l < finest; ++l) {
    const int m = mapSize(l);
    const int from = std::min(l + 2, finest);
    const double capCos = std::max(-1.0, 1.0 - kPi / (static_cast<double>(m) * m));  // 2π(1 − cos r) = 2π²/M²
    const std::size_t base = shared::prefilterOffset(static_cast<shared::uint>(l));
    glm::dvec3 filteredSum(0.0), boxSum(0.0);
    for (int row = 0; row < m; ++row) {
      const double dOmega = pixelSolidAngle(l, row);
      for (int col = 0; col < m; ++col) {
        const glm::dvec3 d = sphericalToDirection(rowTheta(l, row), colPhi(l, col));
        const glm::dvec3 helper = std::abs(d.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
        const glm::dvec3 e1 = glm::normalize(glm::cross(helper, d)), e2 = glm::cross(d, e1);
        // kCapSamples directions uniform in solid angle over the cap: a Vogel
        // spiral in (1 − cos a, b).
        glm::dvec3 sum(0.0);
        for (int i = 0; i < kCapSamples; ++i) {
          const double cosA = 1.0 - (i + 0.5) / kCapSamples * (1.0 - capCos);
          const double sinA = std::sqrt(std::max(0.0, 1.0 - cosA * cosA));
          const double b = i * kGoldenAngle;
          const glm::dvec3 w = cosA * d + sinA * (std::cos(b) * e1 + std::sin(b) * e2);
          sum += glm::dvec3(box.sampleLevel(from, glm::vec3(w)));
        }
        const std::size_t k = base + static_cast<std::size_t>(row) * static_cast<std::size_t>(m) + static_cast<std::size_t>(col);
        const glm::dvec3 mean = sum / static_cast<double>(kCapSamples);
        out.texels_[k] = glm::vec4(glm::vec3(mean), 0.0f);
        filteredSum += mean * dOmega;
        boxSum += glm::dvec3(box.texels_[k]) * dOmega;
      }
    }
    // A convolution with a normalised kernel keeps the integral; the
    // spiral's quadrature nearly does, and this makes it exact.
    for (int c = 0; c < 3; ++c) {
      const double scale = filteredSum[c] > 0.0 ? boxSum[c] / filteredSum[c] : 1.0;
      for (std::size_t k = 0; k < static_cast<std::size_t>(m) * static_cast<std::size_t>(m); ++k) {
        out.texels_[base + k][c] = static_cast<float>(out.texels_[base + k][c] * scale);
      }
    }
  }
  return out;
}

glm::vec3 PrefilteredLight::sampleLevel(int level, const glm::vec3& d) const {
  HC_CHECK_LE(level, finest_);
  const float theta = std::atan2(std::sqrt(d.x * d.x + d.z * d.z), d.y);
  const float phi = std::atan2(d.x, d.z);
  const shared::LatLongTaps t = shared::latLongTaps(static_cast<shared::uint>(level), theta, phi);
  const glm::vec4* map = texels_.data() + shared::prefilterOffset(static_cast<shared::uint>(level));
  const shared::uint m = 1u << level;
  const glm::vec3 a(map[t.row0 * m + t.col0]), b(map[t.row0 * m + t.col1]);
  const glm::vec3 c(map[t.row1 * m + t.col0]), e(map[t.row1 * m + t.col1]);
  const glm::vec3 top = t.tCol * (b - a) + a;
  const glm::vec3 bottom = t.tCol * (e - c) + c;
  return t.tRow * (bottom - top) + top;
}

glm::vec3 PrefilteredLight::sample(float level, const glm::vec3& direction) const {
  const float lambda = std::clamp(level, 0.0f, static_cast<float>(finest_));
  const int l0 = static_cast<int>(lambda);
  const float t = lambda - static_cast<float>(l0);
  const glm::vec3 a = sampleLevel(l0, direction);
  if (t == 0.0f || l0 == finest_) return a;
  return a + t * (sampleLevel(l0 + 1, direction) - a);
}

glm::vec3 PrefilteredLight::lobe(const shared::SliceLobe& lobe, const glm::vec3& axis, const glm::vec3& u,
                                 const glm::vec3& v) const {
  glm::vec3 sum(0.0f);
  for (shared::uint i = 0; i < shared::kLobeSamples; ++i) {
    const glm::vec4& s = lobe.samples[i];
    const glm::vec3 d = std::cos(s.x) * axis + std::sin(s.x) * (std::cos(s.y) * u + std::sin(s.y) * v);
    sum += s.w * sample(s.z, d);
  }
  return sum;
}

}  // namespace haarcast
