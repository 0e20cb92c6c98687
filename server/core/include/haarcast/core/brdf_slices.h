// The unrotated BRDF slice table (DESIGN.md "BRDF slices"): for each of T
// outgoing elevations θₒ, the local-frame map ρ(ωᵢ, ωₒ)·cos θᵢ with ωₒ at
// φ = 0, Haar-coded. These are the only BRDF coefficients haarcast stores;
// every rotation happens at run time.
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "haarcast/core/brdf.h"
#include "haarcast/core/haar.h"

namespace haarcast {

struct SliceTableOptions {
  int level = 5;
  int thetaSamples = 16;      // T
  int supersampling = 4;      // per pixel: n×n stratified samples averaged
};

class BrdfSliceTable {
 public:
  int level() const { return level_; }
  int thetaSamples() const { return static_cast<int>(thetaOut_.size()); }
  static constexpr int kChannels = 3;

  // θₒ of sample t: (t + ½)·(π/2)/T.
  double thetaOut(int t) const { return thetaOut_[static_cast<std::size_t>(t)]; }
  // Slice nearest to θₒ (clamped to [0, π/2]).
  int nearestSlice(double thetaOut) const;

  const HaarMap& slice(int channel, int t) const;
  // All slices of one channel, in θₒ order (what a SliceRotator takes).
  std::vector<HaarMap> channelSlices(int channel) const;

  std::size_t storedBytes() const;

  // progress(done, total) is called as slices complete (may be empty).
  static BrdfSliceTable build(const Brdf& brdf, const SliceTableOptions& options,
                              const std::function<void(int, int)>& progress = {});

  // A table from slices computed elsewhere (the on-disk cache, haarcast_io's
  // slice_cache.h). slices[channel * T + t], T = thetaOut.size() ≥ 1, all of
  // one level, all finite. thetaOut must be the layout build() uses,
  // (t + ½)·(π/2)/T, because nearestSlice() and the rotators assume it.
  // Throws std::invalid_argument naming the first problem.
  static BrdfSliceTable fromSlices(std::vector<double> thetaOut, std::vector<HaarMap> slices);

 private:
  int level_ = 0;
  std::vector<double> thetaOut_;
  std::vector<HaarMap> slices_;  // [channel * T + t]
};

// The local-frame slice map of one channel at θₒ, pixel values averaged over
// n×n stratified samples per pixel. Shared by the table builder and the
// analytic references of the tests and the rotation report.
SphereMap sliceMap(const Brdf& brdf, double thetaOut, int channel, int level, int supersampling);

// Pixel-averaged map of any function: the solid-angle mean of f over each
// pixel, from n×n stratified positions (uniform in θ and φ within the pixel,
// each weighted by sin θ so that SphereMap::integral stays right).
SphereMap supersampledMap(int level, int supersampling, const std::function<double(const glm::dvec3&)>& f);

// supersampledMap in two steps, for a caller that evaluates f for many
// directions at once (visibility traces them as ray packets). The
// directions, pixel by pixel in raster order and each pixel's n×n θ-major,
// are the order supersampledMeans reads its values in:
//   supersampledMeans(level, n, f at each of supersampledDirections(level, n))
// equals supersampledMap(level, n, f) to the bit. Values must number
// (2^level·n)², else std::invalid_argument.
std::vector<glm::dvec3> supersampledDirections(int level, int supersampling);
SphereMap supersampledMeans(int level, int supersampling, std::span<const double> values);

}  // namespace haarcast
