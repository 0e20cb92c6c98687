// Analytic BRDFs in the local frame (+Y = shading normal).
#pragma once

#include <memory>
#include <string>

#include <glm/vec3.hpp>

namespace haarcast {

class Brdf {
 public:
  virtual ~Brdf() = default;
  // ρ(ωᵢ, ωₒ) per RGB channel for unit local directions; zero when either
  // direction is below the horizon. Without the cosine factor.
  virtual glm::dvec3 evaluate(const glm::dvec3& wi, const glm::dvec3& wo) const = 0;
  virtual std::string name() const = 0;
};

// ρ = albedo/π.
std::unique_ptr<Brdf> makeLambert(const glm::dvec3& albedo);
// Energy-normalised modified Phong: kd/π + ks·(n+2)/(2π)·cos^n(α), α between
// ωᵢ and the mirror reflection of ωₒ about the normal.
std::unique_ptr<Brdf> makePhong(const glm::dvec3& kd, const glm::dvec3& ks, double exponent);
// Normalised Blinn-Phong: kd/π + ks·(n+8)/(8π)·cos^n(θₕ).
std::unique_ptr<Brdf> makeBlinnPhong(const glm::dvec3& kd, const glm::dvec3& ks, double exponent);
// GGX microfacet (Walter et al. 2007) with Smith height-correlated masking
// and Schlick Fresnel: kd/π + D·G·F/(4 cos θᵢ cos θₒ); roughness α ∈ (0, 1].
std::unique_ptr<Brdf> makeGgx(const glm::dvec3& kd, const glm::dvec3& f0, double roughness);

}  // namespace haarcast
