// spatial: inverse Haar → resample at the rotated directions → forward Haar.
#include <cmath>

#include "haarcast/core/rotation.h"
#include "rotators.h"

namespace haarcast {

SphereMap rotateSpatialMap(const SphereMap& f, const EulerYXY& r) {
  // g(ω) = f(Rᵀω): each target pixel centre looks up its source direction.
  const glm::dmat3 rt = glm::transpose(rotationMatrix(r));
  const int level = f.level();
  const int m = f.size();
  SphereMap g(level);
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      const Spherical src = directionToSpherical(rt * sphericalToDirection(rowTheta(level, i), colPhi(level, j)));
      g.at(i, j) = static_cast<float>(f.sampleBilinear(src.theta, src.phi));
    }
  }
  return g;
}

HaarMap rotateSpatial(const HaarMap& f, const EulerYXY& r) {
  return forwardHaar(rotateSpatialMap(inverseHaar(f), r));
}

HaarMap shiftPhi(const HaarMap& f, double radians) {
  const SphereMap src = inverseHaar(f);
  const int m = src.size();
  // Shift in pixels, reduced to [0, m): g(φ) = f(φ − shift).
  double shift = radians / kTwoPi * m;
  shift -= std::floor(shift / m) * m;
  const int whole = static_cast<int>(std::floor(shift));
  const double frac = shift - whole;
  SphereMap g(src.level());
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      const int j0 = ((j - whole) % m + m) % m;       // f at φ_j − whole
      const int j1 = ((j - whole - 1) % m + m) % m;   // one pixel further back
      g.at(i, j) = static_cast<float>((1.0 - frac) * src.at(i, j0) + frac * src.at(i, j1));
    }
  }
  return forwardHaar(g);
}

namespace detail {
namespace {
class SpatialRotator final : public SliceRotator {
 public:
  explicit SpatialRotator(std::vector<HaarMap> slices) : slices_(std::move(slices)) {}
  RotationMethod method() const override { return RotationMethod::Spatial; }
  std::size_t sliceCount() const override { return slices_.size(); }
  int level() const override { return slices_.front().level(); }
  void rotate(std::size_t slice, const EulerYXY& r, HaarMap& out) const override {
    out = rotateSpatial(slices_.at(slice), r);
  }
  std::size_t storedBytes() const override { return coefficientBytes(slices_); }

 private:
  std::vector<HaarMap> slices_;
};
}  // namespace

std::unique_ptr<SliceRotator> makeSpatialRotator(std::vector<HaarMap> slices, const RotatorOptions&) {
  return std::make_unique<SpatialRotator>(std::move(slices));
}
}  // namespace detail

}  // namespace haarcast
