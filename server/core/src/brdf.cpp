// Analytic BRDFs in the local frame: +Y is the shading normal, so cos θ of a
// unit direction is its y component (DESIGN.md "Frames").
//
// Every model returns zero unless both directions lie strictly above the
// horizon: a BRDF is only defined on the upper hemisphere, and the slice
// tables rely on the lower half of every slice being exactly zero.
#include "haarcast/core/brdf.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "haarcast/core/sphere_map.h"

namespace haarcast {
namespace {

double dot(const glm::dvec3& a, const glm::dvec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

bool finiteNonNegative(const glm::dvec3& c) {
  return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && c.x >= 0.0 && c.y >= 0.0 &&
         c.z >= 0.0;
}

void checkColor(const glm::dvec3& c, const char* model, const char* field) {
  if (!finiteNonNegative(c)) {
    throw std::invalid_argument(std::string(model) + ": " + field + " must be finite and non-negative");
  }
}

void checkExponent(double n, const char* model) {
  if (!std::isfinite(n) || n < 0.0) {
    throw std::invalid_argument(std::string(model) + ": exponent must be finite and >= 0, got " +
                                std::to_string(n));
  }
}

bool aboveHorizon(const glm::dvec3& wi, const glm::dvec3& wo) { return wi.y > 0.0 && wo.y > 0.0; }

class Lambert final : public Brdf {
 public:
  explicit Lambert(const glm::dvec3& albedo) : rho_(albedo / kPi) {}
  glm::dvec3 evaluate(const glm::dvec3& wi, const glm::dvec3& wo) const override {
    return aboveHorizon(wi, wo) ? rho_ : glm::dvec3(0.0);
  }
  std::string name() const override { return "lambert"; }

 private:
  glm::dvec3 rho_;
};

// Lafortune & Willems 1994, "Using the modified Phong reflectance model for
// physically based rendering": the lobe (n+2)/(2π)·cos^n α, α the angle between
// ωᵢ and the mirror direction of ωₒ, integrates against cos θᵢ to exactly 1 at
// normal incidence and to less elsewhere (the lobe is clipped by the horizon).
// cos α = ωᵢ·R(ωₒ) = R(ωᵢ)·ωₒ for the reflection R, so the model is reciprocal.
class Phong final : public Brdf {
 public:
  Phong(const glm::dvec3& kd, const glm::dvec3& ks, double n)
      : diffuse_(kd / kPi), specular_(ks * ((n + 2.0) / kTwoPi)), n_(n) {}
  glm::dvec3 evaluate(const glm::dvec3& wi, const glm::dvec3& wo) const override {
    if (!aboveHorizon(wi, wo)) return glm::dvec3(0.0);
    // Mirror of ωₒ about +Y: (−x, y, −z).
    const double cosAlpha = -wi.x * wo.x + wi.y * wo.y - wi.z * wo.z;
    if (cosAlpha <= 0.0) return diffuse_;
    return diffuse_ + specular_ * std::pow(cosAlpha, n_);
  }
  std::string name() const override { return "phong"; }

 private:
  glm::dvec3 diffuse_;
  glm::dvec3 specular_;
  double n_;
};

// Normalised Blinn-Phong (Akenine-Möller, Haines, Hoffman, "Real-Time
// Rendering" 3rd ed., eq. 7.49): ks·(n+8)/(8π)·cos^n θₕ, the usual
// approximation to the normalisation of the half-vector lobe including the
// microfacet 1/(4 cos θd) factor.
class BlinnPhong final : public Brdf {
 public:
  BlinnPhong(const glm::dvec3& kd, const glm::dvec3& ks, double n)
      : diffuse_(kd / kPi), specular_(ks * ((n + 8.0) / (8.0 * kPi))), n_(n) {}
  glm::dvec3 evaluate(const glm::dvec3& wi, const glm::dvec3& wo) const override {
    if (!aboveHorizon(wi, wo)) return glm::dvec3(0.0);
    const glm::dvec3 sum = wi + wo;
    const double len = std::sqrt(dot(sum, sum));
    // len > 0 here: both directions lie above the horizon, so they cannot be opposite.
    const double cosThetaH = sum.y / len;
    return diffuse_ + specular_ * std::pow(cosThetaH, n_);
  }
  std::string name() const override { return "blinn-phong"; }

 private:
  glm::dvec3 diffuse_;
  glm::dvec3 specular_;
  double n_;
};

// Walter, Marschner, Li, Torrance 2007 ("Microfacet models for refraction
// through rough surfaces"), eq. (33): D(h) = α² / (π (cos²θₕ (α² − 1) + 1)²).
// Masking-shadowing: the height-correlated Smith form of Heitz 2014
// ("Understanding the masking-shadowing function...", eq. 99),
// G₂ = 1 / (1 + Λ(ωᵢ) + Λ(ωₒ)), Λ(ω) = (√(1 + α² tan²θ) − 1)/2. Folded with the
// 1/(4 cos θᵢ cos θₒ) of the microfacet BRDF it becomes
//   G₂ / (4 cos θᵢ cos θₒ) = 1 / (2 (cos θₒ·Aᵢ + cos θᵢ·Aₒ)),  A = √(α² + (1−α²)cos²θ)
// which stays finite at grazing angles (no tan θ to overflow).
// Fresnel: Schlick 1994, F = F₀ + (1 − F₀)(1 − ωᵢ·h)⁵.
class Ggx final : public Brdf {
 public:
  Ggx(const glm::dvec3& kd, const glm::dvec3& f0, double alpha)
      : diffuse_(kd / kPi), f0_(f0), alpha2_(alpha * alpha) {}
  glm::dvec3 evaluate(const glm::dvec3& wi, const glm::dvec3& wo) const override {
    if (!aboveHorizon(wi, wo)) return glm::dvec3(0.0);
    const glm::dvec3 sum = wi + wo;
    const glm::dvec3 h = sum / std::sqrt(dot(sum, sum));
    const double cosH = h.y;
    const double t = cosH * cosH * (alpha2_ - 1.0) + 1.0;
    const double d = alpha2_ / (kPi * t * t);
    const double ci = wi.y;
    const double co = wo.y;
    const double ai = std::sqrt(alpha2_ + (1.0 - alpha2_) * ci * ci);
    const double ao = std::sqrt(alpha2_ + (1.0 - alpha2_) * co * co);
    const double visibility = 0.5 / (co * ai + ci * ao);
    const double cosD = std::clamp(dot(wi, h), 0.0, 1.0);
    const double m = 1.0 - cosD;
    const double m5 = (m * m) * (m * m) * m;
    const glm::dvec3 fresnel = f0_ + (glm::dvec3(1.0) - f0_) * m5;
    return diffuse_ + fresnel * (d * visibility);
  }
  std::string name() const override { return "ggx"; }

 private:
  glm::dvec3 diffuse_;
  glm::dvec3 f0_;
  double alpha2_;
};

}  // namespace

std::unique_ptr<Brdf> makeLambert(const glm::dvec3& albedo) {
  checkColor(albedo, "lambert", "albedo");
  return std::make_unique<Lambert>(albedo);
}

std::unique_ptr<Brdf> makePhong(const glm::dvec3& kd, const glm::dvec3& ks, double exponent) {
  checkColor(kd, "phong", "kd");
  checkColor(ks, "phong", "ks");
  checkExponent(exponent, "phong");
  return std::make_unique<Phong>(kd, ks, exponent);
}

std::unique_ptr<Brdf> makeBlinnPhong(const glm::dvec3& kd, const glm::dvec3& ks, double exponent) {
  checkColor(kd, "blinn-phong", "kd");
  checkColor(ks, "blinn-phong", "ks");
  checkExponent(exponent, "blinn-phong");
  return std::make_unique<BlinnPhong>(kd, ks, exponent);
}

std::unique_ptr<Brdf> makeGgx(const glm::dvec3& kd, const glm::dvec3& f0, double roughness) {
  checkColor(kd, "ggx", "kd");
  checkColor(f0, "ggx", "f0");
  if (f0.x > 1.0 || f0.y > 1.0 || f0.z > 1.0) {
    throw std::invalid_argument("ggx: f0 must lie in [0, 1]");
  }
  // α is the GGX width parameter itself (not a "perceptual" roughness squared).
  if (!(roughness > 0.0 && roughness <= 1.0)) {
    throw std::invalid_argument("ggx: roughness must lie in (0, 1], got " + std::to_string(roughness));
  }
  return std::make_unique<Ggx>(kd, f0, roughness);
}

}  // namespace haarcast
