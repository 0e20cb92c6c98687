// The prefiltered light (prefiltered_light.h).
#include "haarcast/core/prefiltered_light.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "haarcast/core/check.h"

namespace haarcast {

PrefilteredLight PrefilteredLight::build(const std::array<SphereMap, 3>& maps) {
  const int finest = maps[0].level();
  if (finest < 0 || finest >= static_cast<int>(shared::kPrefilterLevels)) {
    throw std::invalid_argument("PrefilteredLight: level " + std::to_string(finest) + " is outside 0.." +
                                std::to_string(shared::kPrefilterLevels - 1));
  }
  for (const SphereMap& m : maps) {
    if (m.level() != finest) throw std::invalid_argument("PrefilteredLight: the channels' maps differ in level");
  }
  PrefilteredLight out;
  out.finest_ = finest;
  out.texels_.assign(shared::prefilterOffset(static_cast<shared::uint>(finest + 1)), glm::vec4(0.0f));
  for (int l = 0; l <= finest; ++l) {
    const std::size_t base = shared::prefilterOffset(static_cast<shared::uint>(l));
    for (std::size_t c = 0; c < 3; ++c) {
      const SphereMap level = l == finest ? maps[c] : maps[c].downsampled(l);
      const std::span<const float> v = level.values();
      for (std::size_t k = 0; k < v.size(); ++k) out.texels_[base + k][static_cast<int>(c)] = v[k];
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
  constexpr float kSector = 2.0f * shared::kPiF / static_cast<float>(shared::kLobeSectors);
  glm::vec3 sum(0.0f);
  for (shared::uint k = 0; k < shared::kLobeRings; ++k) {
    const float a = lobe.angle[static_cast<int>(k)];
    const glm::vec3 along = std::cos(a) * axis;
    const float across = std::sin(a);
    for (shared::uint j = 0; j < shared::kLobeSectors; ++j) {
      const float b = shared::lobeAzimuthSectors(k, j) * kSector;
      const glm::vec3 d = along + across * (std::cos(b) * u + std::sin(b) * v);
      sum += sample(lobe.level[static_cast<int>(k)], d);
    }
  }
  return sum / static_cast<float>(shared::kLobeRings * shared::kLobeSectors);
}

}  // namespace haarcast
