#include "haarcast/core/rotation.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <algorithm>
#include <random>

#include "rotators.h"

namespace haarcast {

static glm::dmat3 rotY(double a) {
  const double c = std::cos(a), s = std::sin(a);
  // Columns: R_y(a) sends x̂ → (c, 0, −s), ŷ → ŷ, ẑ → (s, 0, c); it adds a to φ.
  return glm::dmat3(glm::dvec3(c, 0, -s), glm::dvec3(0, 1, 0), glm::dvec3(s, 0, c));
}

static glm::dmat3 rotX(double b) {
  const double c = std::cos(b), s = std::sin(b);
  // ŷ → (0, c, s): tilts +Y toward +Z by b.
  return glm::dmat3(glm::dvec3(1, 0, 0), glm::dvec3(0, c, s), glm::dvec3(0, -s, c));
}

glm::dmat3 rotationMatrix(const EulerYXY& r) { return rotY(r.alpha) * rotX(r.beta) * rotY(r.gamma); }

EulerYXY eulerFromMatrix(const glm::dmat3& m) {
  // m·ŷ = R_y(α)R_x(β)ŷ = (sin β sin α, cos β, sin β cos α) is column 1 of m.
  const glm::dvec3 ny = m[1];
  EulerYXY e;
  e.beta = std::acos(std::clamp(ny.y, -1.0, 1.0));
  if (std::sin(e.beta) > 1e-12) {
    e.alpha = std::atan2(ny.x, ny.z);
    // R_y(γ) = R_x(β)ᵀ R_y(α)ᵀ m; its column 0 is (cos γ, 0, −sin γ).
    const glm::dmat3 ry = glm::transpose(rotX(e.beta)) * glm::transpose(rotY(e.alpha)) * m;
    e.gamma = std::atan2(-ry[0][2], ry[0][0]);
  } else {
    // Gimbal pole. β = 0: m = R_y(α+γ). β = π: R_x(π)R_y(γ) = R_y(−γ)R_x(π), so
    // m = R_y(α−γ)R_x(π). Either way put the whole turn in α; m·x̂ = R_y(α)x̂.
    const glm::dvec3 nx = m[0];
    e.alpha = std::atan2(-nx.z, nx.x);
    e.gamma = 0.0;
  }
  return e;
}

std::vector<EulerYXY> randomRotations(int count, std::uint32_t seed) {
  std::mt19937 rng(seed);
  // Draw through generate_canonical, not a distribution object, so that the
  // list does not depend on the standard library's distribution algorithm.
  auto unit = [&] { return std::generate_canonical<double, 53>(rng); };
  std::vector<EulerYXY> out(static_cast<std::size_t>(std::max(count, 0)));
  for (EulerYXY& r : out) {
    r.alpha = kTwoPi * unit();
    r.beta = std::acos(1.0 - 2.0 * unit());  // cos β uniform: normals uniform on the sphere
    r.gamma = kTwoPi * unit();
  }
  return out;
}

std::string_view methodName(RotationMethod m) {
  switch (m) {
    case RotationMethod::Haar: return "haar";
    case RotationMethod::Spatial: return "spatial";
    case RotationMethod::Matrix: return "matrix";
    case RotationMethod::Table: return "table";
    case RotationMethod::Fused: return "fused";
    case RotationMethod::Splitsum: return "splitsum";
  }
  return "?";
}

std::optional<RotationMethod> parseRotationMethod(std::string_view name) {
  for (RotationMethod m : kAllPixelMethods)
    if (methodName(m) == name) return m;
  return std::nullopt;
}

std::string pixelMethodNames() {
  std::string out;
  for (RotationMethod m : kAllPixelMethods) out += (out.empty() ? "" : ", ") + std::string(methodName(m));
  return out;
}

std::string_view variantName(HaarVariant v) {
  switch (v) {
    case HaarVariant::Faithful: return "faithful";
    case HaarVariant::Local: return "local";
    case HaarVariant::Refined: return "refined";
  }
  return "?";
}

std::optional<HaarVariant> parseHaarVariant(std::string_view name) {
  if (name == "faithful") return HaarVariant::Faithful;
  if (name == "local") return HaarVariant::Local;
  if (name == "refined") return HaarVariant::Refined;
  return std::nullopt;
}

namespace detail {
void checkSlices(const std::vector<HaarMap>& slices, const char* who) {
  if (slices.empty()) throw std::invalid_argument(std::string(who) + ": no slices to rotate");
  for (const auto& s : slices) {
    if (s.level() != slices.front().level()) {
      throw std::invalid_argument(std::string(who) + ": slices mix levels " + std::to_string(s.level()) + " and " +
                                  std::to_string(slices.front().level()));
    }
  }
}
}  // namespace detail

std::unique_ptr<SliceRotator> makeRotator(RotationMethod method, std::vector<HaarMap> slices,
                                          const RotatorOptions& options) {
  detail::checkSlices(slices, "makeRotator");
  switch (method) {
    case RotationMethod::Haar: return detail::makeHaarRotator(std::move(slices), options);
    case RotationMethod::Spatial: return detail::makeSpatialRotator(std::move(slices), options);
    case RotationMethod::Matrix: return detail::makeMatrixRotator(std::move(slices), options);
    case RotationMethod::Table: return detail::makeTableRotator(std::move(slices), options);
    case RotationMethod::Fused:
      throw std::invalid_argument("makeRotator: fused rotates no coefficients (it samples the slice per pixel, core/fused.h)");
    case RotationMethod::Splitsum:
      throw std::invalid_argument("makeRotator: splitsum keeps no slices (it reads the prefiltered light, core/splitsum.h)");
  }
  throw std::invalid_argument("makeRotator: unknown method");
}

}  // namespace haarcast
