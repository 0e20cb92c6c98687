// table: the storage baseline of Ng, Ramamoorthi, Hanrahan 2004 ("Triple
// product wavelet integrals for all-frequency relighting"), who keep every BRDF
// slice pre-rotated for a discretised set of normals — in the seed's words
// "6-dimensional BRDFs and gigabytes of storage". Rotation is then a lookup.
//
// The grid. A Y-X-Y rotation is g = shift_α ∘ elevate_β ∘ shift_γ (f)
// (rotation.h): β is the normal's elevation, α its azimuth, γ the spin of the
// slice about the normal. The table stores, per slice, the copies rotated by
// (0, β_k, γ_j) with β_k = kπ/(Kβ−1) (0 and π included) and γ_j = 2πj/Kγ. The
// normal's azimuth α is not tabulated: on lat-long maps it is shiftPhi, a pixel
// permutation (exact for whole pixels, linear along φ otherwise), as cheap as
// the lookup itself. A tabulated α axis would multiply storage by its size and
// only replace that exact shift by a snap to the nearest sample; without it,
// pure whole-pixel φ-shifts are exact and only β and γ are snapped.
//
// The lookup. The rotation is first canonicalised with
// eulerFromMatrix(rotationMatrix(r)), so every Euler triple of one rotation
// finds the same copy; at the poles (β = 0 or π) that puts the whole turn in α,
// which the exact shift then applies. Then the nearest β_k and the nearest γ_j
// (wrapping around 2π) pick the copy, and shiftPhi applies α.
#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "haarcast/core/rotation.h"
#include "haarcast/core/parallel.h"
#include "rotators.h"

namespace haarcast::detail {
namespace {

// Past this many bytes of copies the rotator refuses to precompute rather than
// exhaust memory (level 6 with the default 9×16 grid takes 2.4 MB per slice;
// level 8, 38 MB per slice).
constexpr double kMaxTableBytes = 8.0 * 1024 * 1024 * 1024;

class TableRotator final : public SliceRotator {
 public:
  TableRotator(std::vector<HaarMap> slices, const RotatorOptions& options)
      : level_(slices.front().level()),
        sliceCount_(slices.size()),
        elevations_(options.tableElevations),
        spins_(options.tableSpins),
        copies_(sliceCount_ * static_cast<std::size_t>(elevations_) * static_cast<std::size_t>(spins_)) {
    precompute(slices);
  }

  RotationMethod method() const override { return RotationMethod::Table; }
  std::size_t sliceCount() const override { return sliceCount_; }
  int level() const override { return level_; }

  void rotate(std::size_t slice, const EulerYXY& r, HaarMap& out) const override {
    if (slice >= sliceCount_) {
      throw std::out_of_range("table rotator: slice " + std::to_string(slice) + " of " + std::to_string(sliceCount_));
    }
    const EulerYXY e = eulerFromMatrix(rotationMatrix(r));
    const long k = std::clamp(std::lround(e.beta / kPi * (elevations_ - 1)), 0L, static_cast<long>(elevations_ - 1));
    const long j = ((std::lround(e.gamma / kTwoPi * spins_) % spins_) + spins_) % spins_;
    out = shiftPhi(copies_[index(slice, static_cast<int>(k), static_cast<int>(j))], e.alpha);
  }

  int elevations() const { return elevations_; }
  int spins() const { return spins_; }
  const std::vector<HaarMap>& copies() const { return copies_; }

  // The copies are all it keeps: the (β_0, γ_0) copy is the unrotated slice
  // (to float rounding).
  std::size_t storedBytes() const override { return coefficientBytes(copies_); }

 private:
  std::size_t index(std::size_t slice, int k, int j) const {
    return (slice * static_cast<std::size_t>(elevations_) + static_cast<std::size_t>(k)) *
               static_cast<std::size_t>(spins_) +
           static_cast<std::size_t>(j);
  }

  // Every copy is one rotateSpatial call, spread over hardware_concurrency
  // threads by parallelFor.
  void precompute(const std::vector<HaarMap>& slices) {
    const std::size_t perSlice = static_cast<std::size_t>(elevations_) * static_cast<std::size_t>(spins_);
    parallelFor(copies_.size(), [&](std::size_t c) {
      const int k = static_cast<int>(c % perSlice) / spins_;
      const int j = static_cast<int>(c % perSlice) % spins_;
      const EulerYXY r{0.0, kPi * k / (elevations_ - 1), kTwoPi * j / spins_};
      copies_[c] = rotateSpatial(slices[c / perSlice], r);
    });
  }

  int level_;
  std::size_t sliceCount_;
  int elevations_;               // Kβ
  int spins_;                    // Kγ
  std::vector<HaarMap> copies_;  // copies_[index(slice, k, j)]: slice rotated by (0, β_k, γ_j)
};

}  // namespace

std::unique_ptr<SliceRotator> makeTableRotator(std::vector<HaarMap> slices, const RotatorOptions& options) {
  checkSlices(slices, "table rotator");
  if (options.tableElevations < 2) {
    throw std::invalid_argument("table rotator: tableElevations must be at least 2 (β = 0 and π), got " +
                                std::to_string(options.tableElevations));
  }
  if (options.tableSpins < 1) {
    throw std::invalid_argument("table rotator: tableSpins must be at least 1, got " +
                                std::to_string(options.tableSpins));
  }
  const double bytes = static_cast<double>(slices.size()) * options.tableElevations * options.tableSpins *
                       static_cast<double>(slices.front().coefficientCount()) * sizeof(float);
  if (bytes > kMaxTableBytes) {
    throw std::invalid_argument("table rotator: " + std::to_string(slices.size()) + " slices × " +
                                std::to_string(options.tableElevations) + " elevations × " +
                                std::to_string(options.tableSpins) + " spins at level " +
                                std::to_string(slices.front().level()) + " would hold " +
                                std::to_string(static_cast<long long>(bytes / (1024 * 1024))) + " MiB, over the " +
                                std::to_string(static_cast<long long>(kMaxTableBytes / (1024 * 1024))) +
                                " MiB budget; use a lower level or a coarser grid");
  }
  return std::make_unique<TableRotator>(std::move(slices), options);
}

}  // namespace haarcast::detail

namespace haarcast {

TableCopies tableCopies(const SliceRotator& r) {
  const auto* table = dynamic_cast<const detail::TableRotator*>(&r);
  if (table == nullptr) {
    throw std::invalid_argument("tableCopies: the rotator's method is " + std::string(methodName(r.method())) +
                                ", not table");
  }
  return {table->elevations(), table->spins(), table->copies()};
}

}  // namespace haarcast
