// `splitsum` (splitsum.h).
#include "haarcast/core/splitsum.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/vec4.hpp>

#include "haarcast/core/sphere_map.h"

namespace haarcast {

std::vector<double> lobeThetaOut(int thetaSamples) {
  if (thetaSamples < 1) throw std::invalid_argument("lobeThetaOut: " + std::to_string(thetaSamples) + " θₒ samples");
  std::vector<double> out;
  for (int t = 0; t < thetaSamples; ++t) out.push_back((t + 0.5) * (kPi / 2.0) / thetaSamples);
  return out;
}

glm::vec3 splitsumMirror(const glm::mat3& toLight, const EulerYXY& r, double thetaOut) {
  const glm::vec3 local(0.0f, static_cast<float>(std::cos(thetaOut)), static_cast<float>(-std::sin(thetaOut)));
  return toLight * (glm::mat3(rotationMatrix(r)) * local);
}

std::array<float, 3> splitsumShade(const LobePath& path, const shared::SliceBlend& blend, const EulerYXY& r,
                                   double thetaOut, std::uint32_t word) {
  if ((word & shared::kLobeSeenBit) == 0u) return {0.0f, 0.0f, 0.0f};
  const shared::SliceLobe lobe = shared::blendLobes(path.lobes[blend.first], path.lobes[blend.second], blend.weight);
  const glm::vec3 light =
      path.light->sample(shared::splitsumLevel(lobe.median.x), splitsumMirror(path.toLight, r, thetaOut));
  return {lobe.energy.r * light.r, lobe.energy.g * light.g, lobe.energy.b * light.b};
}

std::size_t splitsumStoredBytes(int thetaSamples) {
  return static_cast<std::size_t>(thetaSamples) * sizeof(shared::SliceLobe);
}

std::size_t splitsumPixelBytes() { return 2 * sizeof(shared::SliceLobe) + 8 * sizeof(glm::vec4); }

}  // namespace haarcast
