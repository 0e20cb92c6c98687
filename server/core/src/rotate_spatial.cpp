// spatial: inverse Haar → resample at the rotated directions → forward Haar.
#include <cmath>
#include <stdexcept>

#include "haarcast/core/parallel.h"

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

std::array<SphereMap, 3> rotateSpatialMapsDown(const std::array<SphereMap, 3>& maps, const EulerYXY& r, int level) {
  const glm::dmat3 rt = glm::transpose(rotationMatrix(r));
  const int fine = maps[0].level();
  if (maps[1].level() != fine || maps[2].level() != fine) {
    throw std::invalid_argument("rotateSpatialMapsDown: the three maps are at different levels");
  }
  const int m = maps[0].size();
  std::array<SphereMap, 3> turned{SphereMap(fine), SphereMap(fine), SphereMap(fine)};
  parallelFor(static_cast<std::size_t>(m), [&](std::size_t row) {
    const int i = static_cast<int>(row);
    for (int j = 0; j < m; ++j) {
      const Spherical src = directionToSpherical(rt * sphericalToDirection(rowTheta(fine, i), colPhi(fine, j)));
      const BilinearTaps t = bilinearTaps(fine, src.theta, src.phi);
      for (std::size_t c = 0; c < 3; ++c) {
        const SphereMap& f = maps[c];
        // SphereMap::sampleBilinear's sum, in its order.
        const double top = (1.0 - t.tCol) * f.at(t.row[0], t.col[0]) + t.tCol * f.at(t.row[0], t.col[1]);
        const double bottom = (1.0 - t.tCol) * f.at(t.row[1], t.col[0]) + t.tCol * f.at(t.row[1], t.col[1]);
        turned[c].at(i, j) = static_cast<float>((1.0 - t.tRow) * top + t.tRow * bottom);
      }
    }
  });
  if (level == fine) return turned;
  for (SphereMap& map : turned) map = map.downsampled(level);
  return turned;
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
