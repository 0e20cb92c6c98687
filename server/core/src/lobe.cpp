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

// f(ω)·ΔΩ over a polar grid about `centre`, azimuth b from u toward v: the
// cap of half-angle kInnerAngle (ring 0, sector 0), then kRings rings
// log-spaced out to π, kSectors cells each.
template <typename Visit>
void forEachCell(const glm::dvec3& centre, const glm::dvec3& u, const glm::dvec3& v, const Visit& visit) {
  visit(centre, kTwoPi * (1.0 - std::cos(kInnerAngle)), 0, 0);
  const double ratio = std::pow(kPi / kInnerAngle, 1.0 / kRings);
  double a0 = kInnerAngle;
  for (int ring = 0; ring < kRings; ++ring) {
    const double a1 = ring + 1 == kRings ? kPi : a0 * ratio;
    const double a = 0.5 * (a0 + a1);
    const double dOmega = (std::cos(a0) - std::cos(a1)) * kTwoPi / kSectors;
    const double sa = std::sin(a), ca = std::cos(a);
    for (int s = 0; s < kSectors; ++s) {
      const double b = (s + 0.5) * kTwoPi / kSectors;
      visit(ca * centre + sa * (std::cos(b) * u + std::sin(b) * v), dOmega, ring + 1, s);
    }
    a0 = a1;
  }
}

// The ring boundaries of forEachCell: ring r spans [outer(r − 1), outer(r)].
std::vector<double> ringOuterAngles() {
  std::vector<double> outer(kRings + 1, kInnerAngle);
  const double ratio = std::pow(kPi / kInnerAngle, 1.0 / kRings);
  for (int r = 1; r <= kRings; ++r) outer[static_cast<std::size_t>(r)] = r == kRings ? kPi : outer[static_cast<std::size_t>(r) - 1] * ratio;
  return outer;
}

// The point below which the share q of a piecewise-uniform density lies:
// mass[i] spread evenly over [edge[i], edge[i + 1]].
double quantileOf(const std::vector<double>& mass, const std::vector<double>& edge, double q) {
  double total = 0.0;
  for (const double m : mass) total += m;
  if (!(total > 0.0)) return edge.front() + q * (edge.back() - edge.front());
  double below = 0.0;
  for (std::size_t i = 0; i < mass.size(); ++i) {
    const double e = mass[i] / total;
    if (below + e >= q && e > 0.0) return edge[i] + (q - below) / e * (edge[i + 1] - edge[i]);
    below += e;
  }
  return edge.back();
}

// A prefiltered level whose equatorial texels, (π/M)·(2π/M), have the solid angle Ω.
float levelOfSolidAngle(double omega) { return static_cast<float>(0.5 * std::log2(2.0 * kPi * kPi / std::max(omega, 1e-12))); }

}  // namespace

shared::SliceLobe measureLobe(const Brdf& brdf, double thetaOut, double coreAngle) {
  const glm::dvec3 wo(0.0, std::cos(thetaOut), std::sin(thetaOut));
  // The axis is the mirror direction: a microfacet lobe peaks there, while
  // its mean is pulled toward the normal by its tail and the horizon's cut
  // (by 2° at 87° for GGX 0.02), which shows as a shifted highlight.
  const glm::dvec3 axis(0.0, wo.y, -wo.z);
  const glm::dvec3 u(1.0, 0.0, 0.0), v = glm::cross(axis, u);  // lobeShade's frame
  auto f = [&](const glm::dvec3& wi) { return wi.y > 0.0 ? brdf.evaluate(wi, wo) * wi.y : glm::dvec3(0.0); };
  // The energy, and its luminance per cell of the polar grid.
  glm::dvec3 energy(0.0), core(0.0);
  std::vector<double> cell(static_cast<std::size_t>(kRings + 1) * kSectors, 0.0), ringEnergy(kRings + 1, 0.0);
  forEachCell(axis, u, v, [&](const glm::dvec3& w, double dOmega, int ring, int sector) {
    const glm::dvec3 e = f(w) * dOmega;
    energy += e;
    if (glm::dot(w, axis) >= std::cos(coreAngle)) core += e;
    const double y = luminance(e);
    cell[static_cast<std::size_t>(ring) * kSectors + static_cast<std::size_t>(sector)] = y;
    ringEnergy[static_cast<std::size_t>(ring)] += y;
  });
  std::vector<double> ringEdge(kRings + 2, 0.0);
  const std::vector<double> outer = ringOuterAngles();
  for (int r = 0; r <= kRings; ++r) ringEdge[static_cast<std::size_t>(r) + 1] = outer[static_cast<std::size_t>(r)];
  auto quantile = [&](double q) { return quantileOf(ringEnergy, ringEdge, q); };

  shared::SliceLobe lobe{};
  lobe.energy = glm::vec4(glm::vec3(energy), static_cast<float>(thetaOut));
  lobe.median = glm::vec4(static_cast<float>(quantile(0.5)), 0.0f, 0.0f, 0.0f);
  lobe.core = glm::vec4(glm::vec3(coreAngle >= kPi ? energy : core), 0.0f);
  constexpr int kJ = static_cast<int>(shared::kLobeSectors);
  // The lobe path's samples. Equal shares of the energy would leave the last
  // share of a heavy-tailed lobe (GGX's falls as θ⁻⁴) one band from a few
  // degrees out to the horizon, read at that band's solid angle: a quarter
  // of the energy smeared over a hemisphere. Bands whose edges double
  // instead (½m, m, 2m, … from the median angle m, the last out to π) keep
  // every band's width near its distance from the axis, each weighted by
  // its share of the energy.
  std::vector<double> bandEdge(shared::kLobeBands + 1);
  bandEdge[0] = 0.0;
  for (int i = 1; i < static_cast<int>(shared::kLobeBands); ++i) {
    bandEdge[static_cast<std::size_t>(i)] = std::min(coreAngle, lobe.median.x * std::ldexp(1.0, i - 2));
  }
  bandEdge[shared::kLobeBands] = std::min(coreAngle, kPi);
  std::vector<double> sectorEdge(kSectors + 1);
  for (int s = 0; s <= kSectors; ++s) sectorEdge[static_cast<std::size_t>(s)] = s * kTwoPi / kSectors;
  double weightSum = 0.0;
  for (int k = 0; k < static_cast<int>(shared::kLobeBands); ++k) {
    const double lo = bandEdge[static_cast<std::size_t>(k)], hi = bandEdge[static_cast<std::size_t>(k) + 1];
    // The band's cells, each ring weighted by the part of it inside [lo, hi].
    auto inBand = [&](int r) {
      const double r0 = ringEdge[static_cast<std::size_t>(r)], r1 = ringEdge[static_cast<std::size_t>(r) + 1];
      return std::max(0.0, std::min(r1, hi) - std::max(r0, lo)) / std::max(r1 - r0, 1e-300);
    };
    std::vector<double> azimuth(kSectors, 0.0);
    double bandEnergy = 0.0;
    for (int r = 0; r <= kRings; ++r) {
      const double w = inBand(r);
      if (w == 0.0) continue;
      for (int s = 0; s < kSectors; ++s) azimuth[static_cast<std::size_t>(s)] += w * cell[static_cast<std::size_t>(r) * kSectors + static_cast<std::size_t>(s)];
    }
    for (const double e : azimuth) bandEnergy += e;
    // J equal shares of the band's energy in azimuth, from b = 0 (u, across
    // the plane of incidence); each sample at its share's median azimuth
    // and at the median angle of the cells in its share, reading the light
    // at the share's solid angle. A lobe is symmetric about the plane of
    // incidence and, stretched at grazing views, thin across it: b = 0 and
    // b = π are where it is thinnest, and with J even they are shares'
    // edges, never a share's median (which would sit where there is no
    // energy).
    for (int j = 0; j < kJ; ++j) {
      const double q = (j + 0.5) / kJ;
      const double qLo = q - 0.5 / kJ, qHi = q + 0.5 / kJ;
      // Azimuths of a share that wraps past 2π stay continuous (b may exceed 2π or go below 0).
      auto az = [&](double x) { return x < 0.0 ? quantileOf(azimuth, sectorEdge, x + 1.0) - kTwoPi
                                        : x > 1.0 ? quantileOf(azimuth, sectorEdge, x - 1.0) + kTwoPi
                                                  : quantileOf(azimuth, sectorEdge, x); };
      const double b = az(q), bLo = az(qLo), bHi = az(qHi);
      std::vector<double> radial(kRings + 1, 0.0);
      for (int s = 0; s < kSectors; ++s) {
        const double c0 = sectorEdge[static_cast<std::size_t>(s)], c1 = sectorEdge[static_cast<std::size_t>(s) + 1];
        // The sector's overlap with [bLo, bHi], trying the share's wraps.
        double overlap = 0.0;
        for (const double shift : {-kTwoPi, 0.0, kTwoPi}) overlap += std::max(0.0, std::min(c1 + shift, bHi) - std::max(c0 + shift, bLo));
        if (overlap <= 0.0) continue;
        for (int r = 0; r <= kRings; ++r) radial[static_cast<std::size_t>(r)] += inBand(r) * overlap * cell[static_cast<std::size_t>(r) * kSectors + static_cast<std::size_t>(s)];
      }
      std::vector<double> edges = ringEdge;
      for (double& e : edges) e = std::clamp(e, lo, hi);
      const double a = quantileOf(radial, edges, 0.5);
      const double omega = (std::cos(lo) - std::cos(hi)) * std::max(bHi - bLo, 1e-9);
      const double w = bandEnergy / kJ;
      weightSum += w;
      lobe.samples[k * kJ + j] = glm::vec4(static_cast<float>(a), static_cast<float>(b), levelOfSolidAngle(omega), static_cast<float>(w));
    }
  }
  for (glm::vec4& s : lobe.samples) s.w = weightSum > 0.0 ? static_cast<float>(s.w / weightSum) : 1.0f / shared::kLobeSamples;
  return lobe;
}

std::vector<shared::SliceLobe> measureLobes(const Brdf& brdf, const std::vector<double>& thetaOut, double coreAngle) {
  std::vector<shared::SliceLobe> out(thetaOut.size());
  parallelFor(thetaOut.size(), [&](std::size_t t) { out[t] = measureLobe(brdf, thetaOut[t], coreAngle); });
  return out;
}

LobeCore chooseLobeCore(const Brdf& brdf, const std::vector<double>& thetaOut, int level) {
  return chooseLobeCore(brdf, thetaOut, level, measureLobes(brdf, thetaOut));
}

LobeCore chooseLobeCore(const Brdf& brdf, const std::vector<double>& thetaOut, int level,
                        std::vector<shared::SliceLobe> lobes) {
  const double texel = kPi / mapSize(level);
  LobeCore out;
  out.lobes = std::move(lobes);
  if (out.lobes.empty() || sharpestMedian(out.lobes) > kLobeMedianTexels * texel) {
    out.lobes.clear();
    return out;
  }
  const double coreAngle = kLobeCoreTexels * texel;
  std::vector<shared::SliceLobe> cores = measureLobes(brdf, thetaOut, coreAngle);
  double tail = 0.0;  // the largest share outside the core
  for (const shared::SliceLobe& lobe : cores) {
    const double e = luminance709(lobe.energy.r, lobe.energy.g, lobe.energy.b);
    if (e > 0.0) tail = std::max(tail, 1.0 - luminance709(lobe.core.r, lobe.core.g, lobe.core.b) / e);
  }
  if (tail < kLobeTailLeft) {
    out.angle = static_cast<float>(kPi);
  } else {
    out.angle = static_cast<float>(coreAngle);
    out.lobes = std::move(cores);
  }
  return out;
}

int chooseLevel(const Brdf& brdf, const std::vector<double>& thetaOut, std::span<const shared::SliceLobe> lobes,
                int cap, int floor) {
  const int n = chooseLevel(lobes, cap, floor);
  const std::vector<shared::SliceLobe> whole(lobes.begin(), lobes.end());
  for (int level = std::min(floor, cap); level < n; ++level) {
    if (chooseLobeCore(brdf, thetaOut, level, whole).angle >= static_cast<float>(kPi)) return level;
  }
  return n;
}

double sharpestMedian(std::span<const shared::SliceLobe> lobes) {
  double sharpest = kPi;
  for (const shared::SliceLobe& lobe : lobes) sharpest = std::min(sharpest, static_cast<double>(lobe.median.x));
  return sharpest;
}

int chooseLevel(std::span<const shared::SliceLobe> lobes, int cap, int floor) {
  floor = std::min(floor, cap);
  // m ≥ K·π/2ⁿ ⇔ n ≥ log₂(K·π/m): the smallest whole n, within [floor, cap].
  const double median = sharpestMedian(lobes);
  if (!(median > 0.0)) return cap;
  const double n = std::ceil(std::log2(kLevelMedianTexels * kPi / median) - 1e-9);
  return static_cast<int>(std::clamp(n, static_cast<double>(floor), static_cast<double>(cap)));
}

}  // namespace haarcast
