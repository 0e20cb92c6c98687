// Lobe measurement (lobe.h).
#include "haarcast/core/lobe.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>

#include "haarcast/core/light_split.h"
#include "haarcast/core/parallel.h"
#include "haarcast/core/sphere_map.h"

namespace haarcast {
namespace {

constexpr int kRings = 240;
constexpr int kSectors = 96;
constexpr double kInnerAngle = 1e-4;  // the central cap: one sample on the axis

double luminance(const glm::dvec3& c) { return luminance709(c.r, c.g, c.b); }

// f(ω)·ΔΩ over a polar grid about `centre`: the cap of half-angle
// kInnerAngle, then kRings rings log-spaced out to π, kSectors cells each.
template <typename Visit>
void forEachCell(const glm::dvec3& centre, const Visit& visit) {
  // An orthonormal frame about the centre.
  const glm::dvec3 helper = std::abs(centre.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
  const glm::dvec3 u = glm::normalize(glm::cross(helper, centre));
  const glm::dvec3 v = glm::cross(centre, u);
  visit(centre, kTwoPi * (1.0 - std::cos(kInnerAngle)), 0, kInnerAngle);
  const double ratio = std::pow(kPi / kInnerAngle, 1.0 / kRings);
  double a0 = kInnerAngle;
  for (int ring = 0; ring < kRings; ++ring) {
    const double a1 = ring + 1 == kRings ? kPi : a0 * ratio;
    const double a = 0.5 * (a0 + a1);
    const double dOmega = (std::cos(a0) - std::cos(a1)) * kTwoPi / kSectors;
    const double sa = std::sin(a), ca = std::cos(a);
    for (int s = 0; s < kSectors; ++s) {
      const double b = (s + 0.5) * kTwoPi / kSectors;
      visit(ca * centre + sa * (std::cos(b) * u + std::sin(b) * v), dOmega, ring + 1, a1);
    }
    a0 = a1;
  }
}

}  // namespace

shared::SliceLobe measureLobe(const Brdf& brdf, double thetaOut) {
  const glm::dvec3 wo(0.0, std::cos(thetaOut), std::sin(thetaOut));
  // The axis is the mirror direction: a microfacet lobe peaks there, while
  // its mean is pulled toward the normal by its tail and the horizon's cut
  // (by 2° at 87° for GGX 0.02), which shows as a shifted highlight.
  const glm::dvec3 axis(0.0, wo.y, -wo.z);
  auto f = [&](const glm::dvec3& wi) { return wi.y > 0.0 ? brdf.evaluate(wi, wo) * wi.y : glm::dvec3(0.0); };

  // The energy, and its luminance per ring of the polar grid (ring 0: the cap).
  glm::dvec3 energy(0.0);
  std::vector<double> ringEnergy(kRings + 1, 0.0), ringOuter(kRings + 1, kInnerAngle);
  forEachCell(axis, [&](const glm::dvec3& w, double dOmega, int ring, double outer) {
    const glm::dvec3 e = f(w) * dOmega;
    energy += e;
    ringEnergy[static_cast<std::size_t>(ring)] += luminance(e);
    ringOuter[static_cast<std::size_t>(ring)] = outer;
  });
  double total = 0.0;
  for (const double e : ringEnergy) total += e;

  // The angle within which the share q of the energy lies, linear inside a ring.
  auto quantile = [&](double q) {
    if (!(total > 0.0)) return kPi / 2.0;
    double below = 0.0, inner = 0.0;
    for (std::size_t r = 0; r < ringEnergy.size(); ++r) {
      const double e = ringEnergy[r] / total;
      if (below + e >= q && e > 0.0) return inner + (q - below) / e * (ringOuter[r] - inner);
      below += e;
      inner = ringOuter[r];
    }
    return kPi;
  };
  shared::SliceLobe lobe{};
  lobe.energy = glm::vec4(glm::vec3(energy), static_cast<float>(thetaOut));
  constexpr int kK = static_cast<int>(shared::kLobeRings);
  for (int k = 0; k < kK; ++k) {
    const double lo = k == 0 ? 0.0 : quantile(static_cast<double>(k) / kK);
    const double hi = quantile(static_cast<double>(k + 1) / kK);
    lobe.angle[k] = static_cast<float>(quantile((k + 0.5) / kK));
    // A sample stands for its share of the ring: that solid angle is a
    // texel of the level whose equatorial texels (π/M)·(2π/M) match it.
    const double perSample = std::max(kTwoPi * (std::cos(lo) - std::cos(hi)) / shared::kLobeSectors, 1e-12);
    lobe.level[k] = static_cast<float>(0.5 * std::log2(2.0 * kPi * kPi / perSample));
  }
  lobe.median = glm::vec4(static_cast<float>(quantile(0.5)), 0.0f, 0.0f, 0.0f);
  return lobe;
}

std::vector<shared::SliceLobe> measureLobes(const Brdf& brdf, const std::vector<double>& thetaOut) {
  std::vector<shared::SliceLobe> out(thetaOut.size());
  parallelFor(thetaOut.size(), [&](std::size_t t) { out[t] = measureLobe(brdf, thetaOut[t]); });
  return out;
}

}  // namespace haarcast
