// Properties of the analytic BRDFs and of the unrotated slice table: each
// test checks something that a plausible mistake (a wrong normalisation, a
// mirrored lobe, a missing cosine, a swapped channel) would break.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/haar.h"

namespace haarcast {
namespace {

constexpr double kDeg = kPi / 180.0;

// ∫ f dω over the upper hemisphere by the midpoint rule in (u = cos θ, φ),
// where dω = du dφ exactly: a lobe is resolved where it is narrow in u.
template <typename F>
auto hemisphereIntegral(const F& f, int nu, int nphi) {
  decltype(f(glm::dvec3(0.0, 1.0, 0.0))) sum{};
  for (int i = 0; i < nu; ++i) {
    const double u = (i + 0.5) / nu;
    const double s = std::sqrt(1.0 - u * u);
    for (int j = 0; j < nphi; ++j) {
      const double phi = (j + 0.5) * kTwoPi / nphi;
      sum += f(glm::dvec3(s * std::sin(phi), u, s * std::cos(phi)));
    }
  }
  return sum * (kTwoPi / (static_cast<double>(nu) * nphi));
}

// Directional albedo ∫ ρ(ωᵢ, ωₒ) cos θᵢ dωᵢ.
glm::dvec3 albedo(const Brdf& brdf, const glm::dvec3& wo, int nu = 512, int nphi = 1024) {
  return hemisphereIntegral([&](const glm::dvec3& wi) { return brdf.evaluate(wi, wo) * wi.y; }, nu, nphi);
}

glm::dvec3 randomDirection(std::mt19937& rng, bool upper) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double u = upper ? uni(rng) : -uni(rng);
  return sphericalToDirection(std::acos(u), kTwoPi * uni(rng));
}

struct Named {
  std::string label;
  std::unique_ptr<Brdf> brdf;
};

std::vector<Named> allModels() {
  std::vector<Named> out;
  out.push_back({"lambert", makeLambert({0.8, 0.5, 0.2})});
  out.push_back({"phong", makePhong({0.1, 0.2, 0.3}, {0.6, 0.5, 0.4}, 40.0)});
  out.push_back({"blinn-phong", makeBlinnPhong({0.1, 0.2, 0.3}, {0.6, 0.5, 0.4}, 80.0)});
  out.push_back({"ggx", makeGgx({0.1, 0.2, 0.3}, {0.9, 0.6, 0.3}, 0.25)});
  return out;
}

void expectVecNear(const glm::dvec3& a, const glm::dvec3& b, double tol, const std::string& what) {
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], b[c], tol) << what << " channel " << c;
}

// Helmholtz reciprocity. The modified Phong lobe is reciprocal too:
// ωᵢ·R(ωₒ) = R(ωᵢ)·ωₒ for the mirror reflection R.
TEST(Brdf, Reciprocity) {
  std::mt19937 rng(7);
  for (const Named& m : allModels()) {
    for (int k = 0; k < 2000; ++k) {
      const glm::dvec3 a = randomDirection(rng, true);
      const glm::dvec3 b = randomDirection(rng, true);
      const glm::dvec3 ab = m.brdf->evaluate(a, b);
      const glm::dvec3 ba = m.brdf->evaluate(b, a);
      for (int c = 0; c < 3; ++c) {
        ASSERT_NEAR(ab[c], ba[c], 1e-12 * std::max(1.0, std::abs(ab[c]))) << m.label << " channel " << c;
      }
    }
  }
}

TEST(Brdf, ZeroBelowTheHorizon) {
  std::mt19937 rng(11);
  for (const Named& m : allModels()) {
    for (int k = 0; k < 500; ++k) {
      const glm::dvec3 up = randomDirection(rng, true);
      const glm::dvec3 down = randomDirection(rng, false);
      EXPECT_EQ(m.brdf->evaluate(down, up), glm::dvec3(0.0)) << m.label;
      EXPECT_EQ(m.brdf->evaluate(up, down), glm::dvec3(0.0)) << m.label;
      EXPECT_EQ(m.brdf->evaluate(down, down), glm::dvec3(0.0)) << m.label;
    }
  }
}

// Values at ωᵢ = ωₒ = n, where every lobe peaks and h = n: the normalisation
// constants of brdf.h, read off directly.
TEST(Brdf, PeakValuesAtNormalIncidence) {
  const glm::dvec3 n(0.0, 1.0, 0.0);
  const glm::dvec3 kd(0.1, 0.2, 0.3), ks(0.6, 0.5, 0.4);
  expectVecNear(makeLambert(kd)->evaluate(n, n), kd / kPi, 1e-15, "lambert");
  expectVecNear(makePhong(kd, ks, 40.0)->evaluate(n, n), kd / kPi + ks * (42.0 / kTwoPi), 1e-12, "phong");
  expectVecNear(makeBlinnPhong(kd, ks, 80.0)->evaluate(n, n), kd / kPi + ks * (88.0 / (8.0 * kPi)), 1e-12,
                "blinn-phong");
  // GGX at h = n: D = 1/(πα²), G₂ = 1, F = F₀, so ρ = kd/π + F₀/(4πα²).
  const double alpha = 0.25;
  const glm::dvec3 f0(0.9, 0.6, 0.3);
  expectVecNear(makeGgx(kd, f0, alpha)->evaluate(n, n), kd / kPi + f0 / (4.0 * kPi * alpha * alpha), 1e-12, "ggx");
}

// The Phong lobe peaks at the mirror direction of ωₒ, i.e. at azimuth φₒ + π.
TEST(Brdf, PhongLobeIsAtTheMirrorDirection) {
  const auto phong = makePhong(glm::dvec3(0.0), glm::dvec3(1.0), 200.0);
  const glm::dvec3 wo = sphericalToDirection(40.0 * kDeg, 0.3);
  const glm::dvec3 mirror = sphericalToDirection(40.0 * kDeg, 0.3 + kPi);
  const double peak = phong->evaluate(mirror, wo).x;
  EXPECT_NEAR(peak, 202.0 / kTwoPi, 1e-9);
  EXPECT_LT(phong->evaluate(sphericalToDirection(45.0 * kDeg, 0.3 + kPi), wo).x, 0.5 * peak);
  EXPECT_LT(phong->evaluate(wo, wo).x, 1e-6 * peak);
}

TEST(Brdf, LambertAlbedo) {
  const glm::dvec3 a(0.8, 0.5, 0.2);
  const auto lambert = makeLambert(a);
  for (double thetaO : {0.0, 30.0, 75.0}) {
    // The midpoint rule in u is exact for a lobe linear in u.
    expectVecNear(albedo(*lambert, sphericalToDirection(thetaO * kDeg, 0.0), 64, 64), a, 1e-12, "lambert");
  }
}

// At normal incidence the mirror direction is the normal, α = θᵢ, and
// ∫ (n+2)/(2π) cosⁿθ cos θ dω = (n+2)/(2π)·2π/(n+2) = 1 exactly, so the
// albedo is kd + ks.
TEST(Brdf, PhongAlbedoAtNormalIncidenceIsKdPlusKs) {
  const glm::dvec3 kd(0.1, 0.2, 0.3), ks(0.6, 0.5, 0.4);
  for (double n : {0.0, 1.0, 10.0, 100.0, 1000.0}) {
    const auto phong = makePhong(kd, ks, n);
    // The integrand is φ-symmetric here; 2·10⁵ steps in u resolve cos¹⁰⁰¹θ
    // (width 10⁻³ in u) to ~10⁻⁶.
    expectVecNear(albedo(*phong, glm::dvec3(0.0, 1.0, 0.0), 200000, 2), kd + ks, 5e-6,
                  "phong n=" + std::to_string(n));
  }
}

// Away from the normal the lobe is clipped by the horizon: albedo < kd + ks.
TEST(Brdf, PhongAlbedoFallsOffAtGrazingAngles) {
  const auto phong = makePhong(glm::dvec3(0.0), glm::dvec3(1.0), 10.0);
  double previous = 1.0 + 1e-6;
  for (double thetaO : {0.0, 30.0, 60.0, 80.0}) {
    const double a = albedo(*phong, sphericalToDirection(thetaO * kDeg, 0.0)).x;
    EXPECT_LT(a, previous) << thetaO;
    previous = a;
  }
  EXPECT_LT(previous, 0.75);
}

// Normalised Blinn-Phong: (n+8)/(8π) is an approximation that overshoots a
// little and tends to 1 as n grows; measured albedo at normal incidence
// 1.0748 (n = 10), 1.0181 (n = 100), 1.0020 (n = 1000).
TEST(Brdf, BlinnPhongAlbedoTendsToKs) {
  double previous = 1.1;
  for (double n : {10.0, 100.0, 1000.0}) {
    const auto bp = makeBlinnPhong(glm::dvec3(0.0), glm::dvec3(1.0), n);
    const double a = albedo(*bp, glm::dvec3(0.0, 1.0, 0.0), 200000, 2).x;
    EXPECT_GT(a, 1.0) << "n=" << n;
    EXPECT_LT(a, previous) << "n=" << n;
    previous = a;
  }
  EXPECT_LT(previous, 1.005);
}

// GGX normalisation ∫ D(h) cos θₕ dωₕ = 1 (Walter et al. 2007, eq. 4). D is
// read back from the BRDF along the retro-reflection ωᵢ = ωₒ = ω, where
// h = ω, F = F₀ = 1 and the height-correlated G₂ = 1/(1 + 2Λ(θ)) with
// Λ = (√(1 + α² tan²θ) − 1)/2 (Heitz 2014): D(θ) = ρ(ω, ω)·4 cos²θ·√(1 + α² tan²θ).
// A wrong D, G or their product fails this.
TEST(Brdf, GgxDistributionIsNormalised) {
  for (double alpha : {0.05, 0.2, 0.5, 1.0}) {
    const auto ggx = makeGgx(glm::dvec3(0.0), glm::dvec3(1.0), alpha);
    const double integral = hemisphereIntegral(
        [&](const glm::dvec3& w) {
          const double c = w.y;
          const double tan2 = (1.0 - c * c) / (c * c);
          const double d = ggx->evaluate(w, w).x * 4.0 * c * c * std::sqrt(1.0 + alpha * alpha * tan2);
          return d * c;
        },
        40000, 4);
    EXPECT_NEAR(integral, 1.0, 1e-4) << "alpha=" << alpha;
  }
}

// With F = 1 and no diffuse term, a microfacet BRDF with height-correlated
// masking reflects at most what arrives (it loses the multiply scattered
// part), and nearly all of it for a smooth surface at normal incidence.
TEST(Brdf, GgxConservesEnergy) {
  for (double alpha : {0.1, 0.5, 1.0}) {
    const auto ggx = makeGgx(glm::dvec3(0.0), glm::dvec3(1.0), alpha);
    for (double thetaO : {0.0, 30.0, 60.0, 80.0}) {
      const double a = albedo(*ggx, sphericalToDirection(thetaO * kDeg, 0.0)).x;
      EXPECT_LE(a, 1.0 + 1e-3) << "alpha=" << alpha << " thetaO=" << thetaO;
      EXPECT_GT(a, 0.3) << "alpha=" << alpha << " thetaO=" << thetaO;
    }
  }
  const auto smooth = makeGgx(glm::dvec3(0.0), glm::dvec3(1.0), 0.1);
  EXPECT_GT(albedo(*smooth, glm::dvec3(0.0, 1.0, 0.0)).x, 0.98);
  // The diffuse term adds exactly kd.
  const auto both = makeGgx(glm::dvec3(0.25), glm::dvec3(1.0), 0.5);
  const auto specOnly = makeGgx(glm::dvec3(0.0), glm::dvec3(1.0), 0.5);
  const glm::dvec3 wo = sphericalToDirection(50.0 * kDeg, 0.0);
  EXPECT_NEAR(albedo(*both, wo).x - albedo(*specOnly, wo).x, 0.25, 1e-6);
}

// Schlick: F = F₀ at normal incidence on the microfacet, → 1 at grazing.
TEST(Brdf, GgxFresnelTendsToOneAtGrazingAngles) {
  const auto dark = makeGgx(glm::dvec3(0.0), glm::dvec3(0.04), 0.3);
  const auto white = makeGgx(glm::dvec3(0.0), glm::dvec3(1.0), 0.3);
  const glm::dvec3 n(0.0, 1.0, 0.0);
  EXPECT_NEAR(dark->evaluate(n, n).x / white->evaluate(n, n).x, 0.04, 1e-12);
  // Mirror pair at 89°: ωᵢ·h = cos 89°, F = 0.04 + 0.96·(1 − cos 89°)⁵ ≈ 0.92.
  const glm::dvec3 wo = sphericalToDirection(89.0 * kDeg, 0.0);
  const glm::dvec3 wi = sphericalToDirection(89.0 * kDeg, kPi);
  const double m = 1.0 - std::cos(89.0 * kDeg);
  EXPECT_NEAR(dark->evaluate(wi, wo).x / white->evaluate(wi, wo).x, 0.04 + 0.96 * std::pow(m, 5), 1e-12);
}

TEST(Brdf, RejectsBadParameters) {
  const glm::dvec3 ok(0.5);
  EXPECT_THROW(makeLambert({-0.1, 0.5, 0.5}), std::invalid_argument);
  EXPECT_THROW(makeLambert({NAN, 0.5, 0.5}), std::invalid_argument);
  EXPECT_THROW(makePhong(ok, ok, -1.0), std::invalid_argument);
  EXPECT_THROW(makeBlinnPhong(ok, ok, INFINITY), std::invalid_argument);
  EXPECT_THROW(makeGgx(ok, ok, 0.0), std::invalid_argument);
  EXPECT_THROW(makeGgx(ok, ok, 1.5), std::invalid_argument);
  EXPECT_THROW(makeGgx(ok, ok, NAN), std::invalid_argument);
  EXPECT_THROW(makeGgx(ok, {1.2, 0.5, 0.5}, 0.5), std::invalid_argument);
  EXPECT_EQ(makeGgx(ok, ok, 1.0)->name(), "ggx");
}

// ---------------------------------------------------------------------------
// The slice table.

SliceTableOptions smallOptions(int level = 5, int t = 8, int ss = 4) {
  SliceTableOptions o;
  o.level = level;
  o.thetaSamples = t;
  o.supersampling = ss;
  return o;
}

// The table's slice integrates to the directional albedo at its θₒ, computed
// independently by quadrature: checks the cosine factor, the φ = 0 placement
// of ωₒ, the channel order and the Haar round trip at once. Largest relative
// error measured: 7.1e-4, at the most grazing θₒ = 84° (level 5, 4×4 samples
// per pixel, GGX α = 0.3); 1.5e-4 or less for θₒ ≤ 73°.
TEST(BrdfSliceTable, SliceIntegralsMatchQuadrature) {
  const auto ggx = makeGgx({0.2, 0.1, 0.05}, {0.9, 0.6, 0.3}, 0.3);
  const BrdfSliceTable table = BrdfSliceTable::build(*ggx, smallOptions());
  for (int t = 0; t < table.thetaSamples(); ++t) {
    const glm::dvec3 reference = albedo(*ggx, sphericalToDirection(table.thetaOut(t), 0.0));
    for (int c = 0; c < BrdfSliceTable::kChannels; ++c) {
      const double fromTable = inverseHaar(table.slice(c, t)).integral();
      EXPECT_NEAR(fromTable, reference[c], 2e-3 * reference[c]) << "t=" << t << " channel " << c;
    }
  }
}

TEST(BrdfSliceTable, LayoutAndSizes) {
  const auto phong = makePhong({0.1, 0.2, 0.3}, {0.5, 0.4, 0.3}, 20.0);
  const BrdfSliceTable table = BrdfSliceTable::build(*phong, smallOptions(4, 6, 2));
  EXPECT_EQ(table.level(), 4);
  EXPECT_EQ(table.thetaSamples(), 6);
  EXPECT_EQ(table.storedBytes(), 3u * 6u * 16u * 16u * sizeof(float));
  for (int t = 0; t < 6; ++t) EXPECT_DOUBLE_EQ(table.thetaOut(t), (t + 0.5) * (kPi / 2.0) / 6.0);
  for (int c = 0; c < 3; ++c) {
    const std::vector<HaarMap> slices = table.channelSlices(c);
    ASSERT_EQ(slices.size(), 6u);
    for (int t = 0; t < 6; ++t) {
      const auto a = slices[static_cast<std::size_t>(t)].coefficients();
      const auto b = table.slice(c, t).coefficients();
      EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << c << "," << t;
    }
  }
  // The table holds exactly the Haar coefficients of sliceMap (one definition).
  const HaarMap expected = forwardHaar(sliceMap(*phong, table.thetaOut(3), 1, 4, 2));
  for (std::size_t i = 0; i < expected.coefficientCount(); ++i) {
    EXPECT_FLOAT_EQ(table.slice(1, 3)[i], expected[i]) << i;
  }
  EXPECT_THROW(static_cast<void>(table.slice(3, 0)), std::out_of_range);
  EXPECT_THROW(static_cast<void>(table.slice(0, 6)), std::out_of_range);
  EXPECT_THROW(static_cast<void>(table.slice(-1, 0)), std::out_of_range);
}

TEST(BrdfSliceTable, NearestSlicePicksTheClosestSample) {
  const auto lambert = makeLambert(glm::dvec3(0.5));
  const BrdfSliceTable table = BrdfSliceTable::build(*lambert, smallOptions(2, 16, 1));
  for (int t = 0; t < 16; ++t) EXPECT_EQ(table.nearestSlice(table.thetaOut(t)), t);
  for (double theta = -0.5; theta < 2.5; theta += 0.001) {
    const int got = table.nearestSlice(theta);
    const double clamped = std::clamp(theta, 0.0, kPi / 2.0);
    double best = 1e9;
    for (int t = 0; t < 16; ++t) best = std::min(best, std::abs(table.thetaOut(t) - clamped));
    EXPECT_NEAR(std::abs(table.thetaOut(got) - clamped), best, 1e-12) << theta;
  }
  EXPECT_EQ(table.nearestSlice(-1.0), 0);
  EXPECT_EQ(table.nearestSlice(3.0), 15);
  EXPECT_THROW(static_cast<void>(BrdfSliceTable{}.nearestSlice(0.5)), std::logic_error);
}

// progress(done, total) runs on the calling thread, once per θₒ sample, in order.
TEST(BrdfSliceTable, BuildReportsProgressToTotal) {
  const auto ggx = makeGgx(glm::dvec3(0.1), glm::dvec3(0.5), 0.4);
  std::vector<int> seen;
  const std::thread::id caller = std::this_thread::get_id();
  bool sameThread = true;
  BrdfSliceTable::build(*ggx, smallOptions(3, 12, 2), [&](int done, int total) {
    EXPECT_EQ(total, 12);
    seen.push_back(done);
    sameThread = sameThread && std::this_thread::get_id() == caller;
  });
  ASSERT_EQ(seen.size(), 12u);
  for (int k = 0; k < 12; ++k) EXPECT_EQ(seen[static_cast<std::size_t>(k)], k + 1);
  EXPECT_TRUE(sameThread);
}

TEST(BrdfSliceTable, BuildPropagatesExceptions) {
  struct Failing final : Brdf {
    glm::dvec3 evaluate(const glm::dvec3&, const glm::dvec3& wo) const override {
      if (wo.y < 0.5) throw std::runtime_error("failing brdf");
      return glm::dvec3(1.0);
    }
    std::string name() const override { return "failing"; }
  };
  EXPECT_THROW(BrdfSliceTable::build(Failing{}, smallOptions(3, 8, 1)), std::runtime_error);
  // An exception from the progress callback stops the build and reaches the caller.
  const auto lambert = makeLambert(glm::dvec3(0.5));
  EXPECT_THROW(BrdfSliceTable::build(*lambert, smallOptions(3, 8, 1),
                                     [](int done, int) {
                                       if (done == 2) throw std::runtime_error("cancelled");
                                     }),
               std::runtime_error);
}

TEST(BrdfSliceTable, RejectsBadOptionsNamingTheField) {
  const auto lambert = makeLambert(glm::dvec3(0.5));
  auto expectNamed = [&](const SliceTableOptions& o, const std::string& field) {
    try {
      BrdfSliceTable::build(*lambert, o);
      ADD_FAILURE() << "no exception for " << field;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  expectNamed(smallOptions(-1, 4, 1), "level");
  expectNamed(smallOptions(kMaxLevel + 1, 4, 1), "level");
  expectNamed(smallOptions(3, 0, 1), "thetaSamples");
  expectNamed(smallOptions(3, 1025, 1), "thetaSamples");
  expectNamed(smallOptions(3, 4, 0), "supersampling");
  expectNamed(smallOptions(3, 4, 65), "supersampling");
  EXPECT_THROW(sliceMap(*lambert, 0.3, 3, 3, 1), std::invalid_argument);
  EXPECT_THROW(supersampledMap(3, 0, [](const glm::dvec3&) { return 1.0; }), std::invalid_argument);
}

// A Lambert slice is (albedo/π)·max(cos θᵢ, 0), whatever θₒ: every slice is
// the same, and the lower half of the map is exactly zero.
TEST(BrdfSliceTable, LambertSlicesAreCosineLobes) {
  const auto lambert = makeLambert({0.9, 0.6, 0.3});
  const SphereMap a = sliceMap(*lambert, 0.1, 0, 4, 4);
  const SphereMap b = sliceMap(*lambert, 1.4, 0, 4, 4);
  for (std::size_t k = 0; k < a.pixelCount(); ++k) EXPECT_EQ(a.values()[k], b.values()[k]);
  for (int i = 8; i < 16; ++i)
    for (int j = 0; j < 16; ++j) EXPECT_EQ(a.at(i, j), 0.0f);
  // Integral = albedo, up to the O(δ²) error of the sin θ-weighted midpoint
  // rule inside each pixel (δ = π/64 here; measured 3.0e-4 relative).
  // Channel 2 holds the third component.
  EXPECT_NEAR(a.integral(), 0.9, 5e-4 * 0.9);
  EXPECT_NEAR(sliceMap(*lambert, 0.5, 2, 4, 4).integral(), 0.3, 5e-4 * 0.3);
}

// The specular peak of a slice lies at the mirror direction (θₒ, π):
// ωₒ sits at φ = 0 (DESIGN.md "BRDF slices").
TEST(BrdfSliceTable, SlicePeakIsAtTheMirrorDirection) {
  const auto phong = makePhong(glm::dvec3(0.0), glm::dvec3(1.0), 300.0);
  const int level = 6;
  for (double thetaO : {20.0 * kDeg, 50.0 * kDeg}) {
    const SphereMap map = sliceMap(*phong, thetaO, 0, level, 2);
    const auto values = map.values();
    const auto best = static_cast<std::size_t>(std::max_element(values.begin(), values.end()) - values.begin());
    const int row = static_cast<int>(best) / map.size();
    const int col = static_cast<int>(best) % map.size();
    EXPECT_NEAR(rowTheta(level, row), thetaO, kPi / map.size());
    EXPECT_NEAR(colPhi(level, col), kPi, kTwoPi / map.size());
  }
}

// Pixel means converge as the per-pixel sample grid is refined. Solid-angle
// weighted L1 distance to a 64×64-sample reference, Blinn-Phong n = 200 at
// level 5; measured 1: 3.1e-2, 2: 7.4e-3, 4: 1.8e-3, 8: 4.5e-4, 16: 1.1e-4
// (∝ n⁻²), against a slice integral of 0.68.
TEST(BrdfSliceTable, SupersampledSliceConverges) {
  const auto bp = makeBlinnPhong(glm::dvec3(0.0), glm::dvec3(1.0), 200.0);
  const int level = 5;
  const double thetaO = 35.0 * kDeg;
  const SphereMap reference = sliceMap(*bp, thetaO, 0, level, 64);
  auto distance = [&](int ss) {
    const SphereMap map = sliceMap(*bp, thetaO, 0, level, ss);
    double sum = 0.0;
    for (int i = 0; i < map.size(); ++i)
      for (int j = 0; j < map.size(); ++j)
        sum += std::abs(map.at(i, j) - reference.at(i, j)) * pixelSolidAngle(level, i);
    return sum;
  };
  double previous = distance(1);
  EXPECT_GT(previous, 1e-3);  // one sample per pixel misses a lobe this narrow
  for (int ss : {2, 4, 8, 16}) {
    const double d = distance(ss);
    EXPECT_LT(d, 0.5 * previous) << "supersampling " << ss;
    previous = d;
  }
  EXPECT_LT(previous, 1e-3 * reference.integral());
}

// supersampledMap averages by solid angle: its integral of a function is the
// integral of that function (∫ cos⁴θ dω = 4π/5), up to the midpoint rule's
// O(δ²) error (δ = π/128 here; measured 1.0e-4 relative). A θ-uniform
// average would be off by the same order at the finest rows but does not
// converge to the integral as δ → 0 for features near a pixel's edge.
TEST(SupersampledMap, IntegralIsTheSolidAngleIntegral) {
  const auto cos4 = [](const glm::dvec3& d) { return std::pow(d.y, 4); };
  const double exact = 4.0 * kPi / 5.0;
  const double coarse = std::abs(supersampledMap(3, 16, cos4).integral() - exact);
  const double fine = std::abs(supersampledMap(3, 64, cos4).integral() - exact);
  EXPECT_LT(coarse, 2e-4 * exact);
  EXPECT_LT(fine, coarse / 8.0);  // O(δ²): 4× finer, measured 16× smaller
  const SphereMap constant = supersampledMap(2, 3, [](const glm::dvec3&) { return 2.5; });
  for (float v : constant.values()) EXPECT_FLOAT_EQ(v, 2.5f);
}

// The two-step form (directions out, values in) is supersampledMap to the
// bit, for every supersampling, and refuses a wrong number of values.
TEST(SupersampledMap, DirectionsThenMeansIsTheSameMap) {
  const auto f = [](const glm::dvec3& d) { return std::exp(3.0 * d.y) * (1.0 + d.x * d.z) + (d.x > 0.2 ? 0.5 : 0.0); };
  for (int n : {1, 2, 3, 4}) {
    const std::vector<glm::dvec3> directions = supersampledDirections(3, n);
    ASSERT_EQ(directions.size(), static_cast<std::size_t>(8 * n) * static_cast<std::size_t>(8 * n));
    std::vector<double> values;
    for (const glm::dvec3& d : directions) values.push_back(f(d));
    const SphereMap twoSteps = supersampledMeans(3, n, values);
    const SphereMap direct = supersampledMap(3, n, f);
    for (std::size_t i = 0; i < direct.pixelCount(); ++i) {
      ASSERT_EQ(twoSteps.values()[i], direct.values()[i]) << "n " << n << " pixel " << i;
    }
    // Pixel by pixel in raster order: pixel 9's n×n samples come after
    // pixels 0…8's, and they lie in row 1, column 1.
    const Spherical s = directionToSpherical(directions[9 * static_cast<std::size_t>(n * n)]);
    EXPECT_EQ(static_cast<int>(s.theta / (kPi / 8.0)), 1) << "n " << n;
    EXPECT_EQ(static_cast<int>(s.phi / (kTwoPi / 8.0)), 1) << "n " << n;
    values.pop_back();
    EXPECT_THROW(supersampledMeans(3, n, values), std::invalid_argument);
  }
  EXPECT_THROW(supersampledDirections(3, 0), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast
