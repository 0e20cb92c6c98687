// splitLight (light_split.h): seeds, regions, lights.
#include "haarcast/core/light_split.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

namespace haarcast {

LightSplit splitLight(const std::array<SphereMap, 3>& light, const LightSplitOptions& o) {
  if (o.maxLights > 32) throw std::invalid_argument("light split: at most 32 lights, asked for " + std::to_string(o.maxLights));
  if (!(o.seedRatio > 0.0) || !(o.growRatio >= 0.0 && o.growRatio <= 1.0) || !(o.maxRadiusDegrees > 0.0) ||
      !(o.minShare >= 0.0 && o.minShare <= 1.0) || (o.parts != 1 && o.parts != 4)) {
    throw std::invalid_argument("light split: options out of range");
  }
  const int level = light[0].level();
  if (light[1].level() != level || light[2].level() != level) {
    throw std::invalid_argument("light split: the three channels are at different levels");
  }
  const int m = mapSize(level);
  const std::size_t n = static_cast<std::size_t>(m) * static_cast<std::size_t>(m);
  LightSplit out;
  out.rest = light;

  std::vector<double> lum(n), solid(static_cast<std::size_t>(m));
  for (int r = 0; r < m; ++r) solid[static_cast<std::size_t>(r)] = pixelSolidAngle(level, r);
  double total = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const int r = static_cast<int>(i) / m, c = static_cast<int>(i) % m;
    lum[i] = luminance709(light[0].at(r, c), light[1].at(r, c), light[2].at(r, c));
    total += std::max(lum[i], 0.0) * solid[static_cast<std::size_t>(r)];
  }
  if (!(total > 0.0) || o.maxLights == 0) return out;
  const double seedLevel = o.seedRatio * total / (4.0 * kPi);

  std::vector<std::size_t> seeds;
  for (std::size_t i = 0; i < n; ++i)
    if (lum[i] >= seedLevel) seeds.push_back(i);
  // Brightest first, ties in map order (a total order: the same lights on every platform).
  std::sort(seeds.begin(), seeds.end(), [&](std::size_t a, std::size_t b) { return lum[a] != lum[b] ? lum[a] > lum[b] : a < b; });

  auto direction = [&](std::size_t i) {
    return sphericalToDirection(rowTheta(level, static_cast<int>(i) / m), colPhi(level, static_cast<int>(i) % m));
  };
  const double cosRadius = std::cos(o.maxRadiusDegrees * kPi / 180.0);
  std::vector<char> claimed(n, 0);
  std::vector<std::size_t> region, stack;
  for (const std::size_t seed : seeds) {
    if (out.lights.size() + o.parts > o.maxLights) break;
    if (claimed[seed]) continue;
    const glm::dvec3 axis = direction(seed);
    const double floorLum = o.growRatio * lum[seed];
    region.clear();
    stack.assign(1, seed);
    claimed[seed] = 1;
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      region.push_back(i);
      const int r = static_cast<int>(i) / m, c = static_cast<int>(i) % m;
      for (int dr = -1; dr <= 1; ++dr) {
        const int rr = r + dr;
        if (rr < 0 || rr >= m) continue;  // θ does not wrap
        for (int dc = -1; dc <= 1; ++dc) {
          const std::size_t j = static_cast<std::size_t>(rr * m + ((c + dc + m) & (m - 1)));
          if (claimed[j] || lum[j] < floorLum || glm::dot(direction(j), axis) < cosRadius) continue;
          claimed[j] = 1;
          stack.push_back(j);
        }
      }
    }
    // The region's power and centre, then its parts: the texels on each side
    // of two planes through the centre (a region of one texel is one part).
    glm::dvec3 centre(0.0);
    double power = 0.0;
    for (const std::size_t i : region) {
      const double w = std::max(lum[i], 0.0) * solid[static_cast<std::size_t>(static_cast<int>(i) / m)];
      power += w;
      centre += w * direction(i);
    }
    // Too faint to be worth a ray per pixel: its texels stay in the map
    // (and stay claimed, so no later seed grows into them).
    if (power < o.minShare * total) continue;
    centre = glm::normalize(centre);
    const glm::dvec3 helper = std::abs(centre.y) < 0.9 ? glm::dvec3(0.0, 1.0, 0.0) : glm::dvec3(1.0, 0.0, 0.0);
    const glm::dvec3 t1 = glm::normalize(glm::cross(helper, centre));
    const glm::dvec3 t2 = glm::cross(centre, t1);
    std::array<DirectionalLight, 4> parts{};
    std::array<glm::dvec3, 4> weighted{};
    for (const std::size_t i : region) {
      const int r = static_cast<int>(i) / m, c = static_cast<int>(i) % m;
      const double w = solid[static_cast<std::size_t>(r)];
      const glm::dvec3 d = direction(i);
      const std::size_t q = o.parts == 1 ? 0 : (glm::dot(d, t1) >= 0.0 ? 1 : 0) + (glm::dot(d, t2) >= 0.0 ? 2 : 0);
      for (std::size_t ch = 0; ch < 3; ++ch) parts[q].power[ch] += light[ch].at(r, c) * w;
      weighted[q] += std::max(lum[i], 0.0) * w * d;
      ++parts[q].texels;
    }
    for (std::size_t q = 0; q < 4; ++q) {
      if (parts[q].texels == 0) continue;
      parts[q].direction = glm::length(weighted[q]) > 0.0 ? glm::normalize(weighted[q]) : centre;
      out.lights.push_back(parts[q]);
    }
    for (const std::size_t i : region)
      for (std::size_t ch = 0; ch < 3; ++ch) out.rest[ch].at(static_cast<int>(i) / m, static_cast<int>(i) % m) = 0.0f;
  }
  return out;
}

LightSplit splitLight(const std::array<SphereMap, 3>& fine, int level, const LightSplitOptions& options) {
  LightSplit out = splitLight(fine, options);
  for (SphereMap& rest : out.rest) rest = rest.downsampled(level);
  return out;
}

}  // namespace haarcast
