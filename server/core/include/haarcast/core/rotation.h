// Rotation of Haar-coded sphere maps: one interface, four methods
// (DESIGN.md "Rotation methods").
//
// A rotation is a Y-X-Y Euler triple (α, β, γ): R = R_y(α) R_x(β) R_y(γ).
// R_y(a) adds a to φ; R_x(b) tilts +Y toward +Z by b. Rotating a map f by R
// gives g(ω) = f(Rᵀω): what f shows at direction d, g shows at R·d. In map
// terms g = shift_α ∘ elevate_β ∘ shift_γ (f). For a BRDF slice tabulated in
// the local frame (+Y = normal), R·ŷ is the shading normal in the object frame:
// its elevation is β and its azimuth α; γ turns the slice about the normal.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>

#include "haarcast/core/haar.h"

namespace haarcast {

struct EulerYXY {
  double alpha = 0.0;  // final φ-shift (azimuth of the normal)
  double beta = 0.0;   // elevation about X (elevation of the normal)
  double gamma = 0.0;  // first φ-shift (spin about the normal)
};

glm::dmat3 rotationMatrix(const EulerYXY& r);

// Euler triple of a rotation matrix, with β ∈ [0, π]. At β = 0 or π the split
// between α and γ is arbitrary; this puts all of it in α (γ = 0).
EulerYXY eulerFromMatrix(const glm::dmat3& m);

// The per-pixel methods (DESIGN.md "Per-pixel methods"). Four of them rotate
// a slice's coefficients (a SliceRotator each); `fused` never forms rotated
// coefficients: it sums the rotated slice against light × visibility in the
// pixel basis (fused.h), the same integral as `spatial` + the triple product.
// `splitsum` rotates nothing and keeps no slices: the image-based lighting of
// real-time engines, the lobe's energy times the prefiltered light along the
// mirror direction (splitsum.h), a baseline for speed and truth.
enum class RotationMethod { Haar, Spatial, Matrix, Table, Fused, Splitsum };

// The methods that make rotated coefficients (makeRotator accepts these).
inline constexpr RotationMethod kAllRotationMethods[] = {RotationMethod::Haar, RotationMethod::Spatial,
                                                         RotationMethod::Matrix, RotationMethod::Table};
// Every per-pixel method a renderer accepts, the default first.
inline constexpr RotationMethod kAllPixelMethods[] = {RotationMethod::Fused, RotationMethod::Haar,
                                                      RotationMethod::Spatial, RotationMethod::Matrix,
                                                      RotationMethod::Table, RotationMethod::Splitsum};
inline constexpr RotationMethod kDefaultPixelMethod = RotationMethod::Fused;

std::string_view methodName(RotationMethod m);
// Accepts exactly the DESIGN.md names: "fused", "haar", "spatial", "matrix", "table",
// and "splitsum".
std::optional<RotationMethod> parseRotationMethod(std::string_view name);
// "fused, haar, spatial, matrix, table, splitsum": for error messages that list the choices.
std::string pixelMethodNames();

// Variants of the seed's method (see rotate_haar.h for what each does).
enum class HaarVariant {
  Faithful,  // the seed as written: start-level details as derivative samples
  Local,     // start level + the level above, finite chain rule
  Refined,   // default: exact differences from all coarser levels, finite chain rule
};
std::string_view variantName(HaarVariant v);
std::optional<HaarVariant> parseHaarVariant(std::string_view name);

struct RotatorOptions {
  // haar: variant and the detail level it starts from (−1 = finest, n−1).
  // Starting k levels coarser costs O(N/4^k) and drops the finer details.
  HaarVariant haarVariant = HaarVariant::Refined;
  int haarStartLevel = -1;
  // matrix (Wang et al. 2006): elevations sampled uniformly in [0, π]
  // (inclusive), and entries below threshold·(largest entry) dropped.
  int matrixElevations = 33;
  double matrixThreshold = 1e-4;
  // table (Ng et al. 2004): pre-rotated copies (0, β, γ) per slice on a grid
  // of normal elevations β ∈ [0, π] (inclusive) × spins γ ∈ [0, 2π); the
  // normal's azimuth α is not tabulated but applied as an exact φ-shift.
  int tableElevations = 9;
  int tableSpins = 16;
};

// A rotator owns whatever its method precomputes for one set of unrotated
// maps (a BRDF slice table) and rotates one of those maps per call. rotate()
// is const and thread-safe.
class SliceRotator {
 public:
  virtual ~SliceRotator() = default;
  virtual RotationMethod method() const = 0;
  virtual std::size_t sliceCount() const = 0;
  virtual int level() const = 0;
  // Writes the coefficients of slice `slice` rotated by r into out (resized).
  virtual void rotate(std::size_t slice, const EulerYXY& r, HaarMap& out) const = 0;
  // Bytes of coefficient data the method keeps: the unrotated maps plus
  // whatever it precomputed (matrices, pre-rotated copies).
  virtual std::size_t storedBytes() const = 0;
  // Of storedBytes(), what does not depend on the maps and is shared by
  // every rotator of the same method, level and options (matrix: the
  // elevation matrices). A scene stores it once, not once per rotator.
  virtual std::size_t sharedBytes() const { return 0; }
};

// Throws std::invalid_argument if slices is empty or mixes levels, or for
// `fused` and `splitsum`, which rotate no coefficients.
std::unique_ptr<SliceRotator> makeRotator(RotationMethod method, std::vector<HaarMap> slices,
                                          const RotatorOptions& options = {});

// ---- The baselines' precomputations, exported --------------------------------
// The GPU backend packs these (gpu/rotation_data.h), so that its table and
// matrix shaders use exactly what the CPU rotators use.

// A table rotator's pre-rotated copies: copies[(slice·elevations + k)·spins + j]
// is the slice rotated by (0, β_k, γ_j), β_k = kπ/(elevations−1),
// γ_j = 2πj/spins. Throws std::invalid_argument unless r is a table rotator.
struct TableCopies {
  int elevations = 0;
  int spins = 0;
  std::span<const HaarMap> copies;
};
TableCopies tableCopies(const SliceRotator& r);

// A matrix rotator's elevation matrices in compressed sparse rows (row = output
// coefficient, columns ascending): matrix k is elevate_{β_k}, β_k = kπ/(K−1),
// acting on Haar coefficients. Throws std::invalid_argument unless r is a
// matrix rotator.
struct SparseMatrixView {
  std::span<const std::uint32_t> rowStart;  // N + 1 offsets
  std::span<const std::uint32_t> column;
  std::span<const float> value;
};
std::vector<SparseMatrixView> elevationMatrixViews(const SliceRotator& r);

// `count` rotations with the normal R·ŷ uniform on the sphere and the spin γ
// uniform, from a fixed-seed generator (std::mt19937): the same list on every
// machine, for reports, tests and benchmarks.
std::vector<EulerYXY> randomRotations(int count, std::uint32_t seed);

// ---- The methods as free functions on a single map -------------------------

// spatial: inverse Haar → bilinear resample at Rᵀω of every pixel centre →
// forward Haar. The seed's ground truth.
HaarMap rotateSpatial(const HaarMap& f, const EulerYXY& r);
SphereMap rotateSpatialMap(const SphereMap& f, const EulerYXY& r);
// Three maps (a light's R, G, B) turned as rotateSpatialMap turns each, the
// taps found once per pixel for the three and the rows on parallelFor's
// threads, then each averaged down to `level` ≤ their level by solid angle
// (SphereMap::downsampled). `fused` turns its light into each object's
// frame this way from a map two levels finer than the object's
// (render/renderer.cpp): turned at the object's own level, the bilinear
// lookups of a coarse map lost or gained up to 6 % of the light's integral
// (a Lambert torus under adams_place_bridge_1k.hdr: 0.94 at level 4, 0.97
// at 5, 1.01 at 6, 1.00 at 7), which showed as a whole object too dark or
// too bright (docs/evaluation.md, "A level per object").
std::array<SphereMap, 3> rotateSpatialMapsDown(const std::array<SphereMap, 3>& maps, const EulerYXY& r, int level);

// A pure φ-shift by `radians`, applied to Haar coefficients: exact (a
// permutation of pixels) when radians is a whole number of pixels, linear
// interpolation along φ otherwise. Used by the baselines for the cheap part
// of a Y-X-Y rotation.
HaarMap shiftPhi(const HaarMap& f, double radians);

}  // namespace haarcast
