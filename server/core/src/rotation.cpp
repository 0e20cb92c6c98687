#include "haarcast/core/rotation.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <algorithm>
#include <random>

#include "haarcast/core/shared_frame.h"
#include "rotators.h"

namespace haarcast {

glm::dmat3 rotationMatrix(const EulerYXY& r) {
  return shared::rotY(r.alpha) * shared::rotX(r.beta) * shared::rotY(r.gamma);
}

EulerYXY eulerFromMatrix(const glm::dmat3& m) {
  const glm::dvec3 e = shared::eulerYXYOf(m);
  EulerYXY out;
  out.alpha = e.x;
  out.beta = e.y;
  out.gamma = e.z;
  return out;
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
