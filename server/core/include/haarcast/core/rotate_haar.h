// `haar`: rotation directly in the Haar domain — the seed's method
// (Alnasser & Foroosh, "Non-linear phase-shifting of Haar wavelets").
//
// The seed's observation: the details of a non-standard Haar transform are
// finite differences of the map. With block corners a b / c d,
//   v = −(column differences along θ summed)/2 ≈ −Δθ·∂f/∂θ,
//   h ≈ −Δφ·∂f/∂φ,   d' = (mixed second difference)/2 ≈ ½ΔθΔφ·∂²f/∂θ∂φ.
// The rotated map is g(θ, φ) = f(Θ(θ, φ), Φ(θ, φ)) (seed eq. 10), so g's
// differences follow from f's by the chain rule (seed eqs. 11–13). Every
// detail of g at a coarser level is then a weighted sum of g's differences —
// a triangle kernel h_t across the band's direction and a box h_s along it
// (seed eqs. 14–16) — and those sums are computed recursively with the
// upsampled kernel [1 2 1] (seed, "Algorithmic optimization"), O(N) in all.
//
// What the seed leaves open, and what haarcast does:
//  * The scaling coefficient is not a difference (see the variants).
//  * A start level coarser than the finest (seed: O(N/4^k)) makes g a map with
//    no details finer than the start level: the rotation of f's low-pass.
//  * The diagonal band comes from the θ-difference of the φ-differences — the
//    seed's "cross-derivative of the horizontal coefficients". Its eq. 13 as
//    printed lacks the ∂²f/∂Θ² and ∂²f/∂Φ² terms that a second-order chain
//    rule needs and the details do not carry; used literally it leaves ~7% of
//    the diagonal band wrong at every level (measured), and the cross-
//    difference keeps h, v and d' describing one map.
//
// Variants:
//  * Faithful — the seed as written: only the start level's details, read as
//    point samples of ∂f/∂θ, ∂f/∂φ at block centres, bilinearly interpolated;
//    g's differences at every pixel boundary by the Jacobian chain rule
//    (eqs. 11–12). The scaling coefficient from the rotation-invariant
//    integral ∫f dω = Σ c_i⟨ψ_i, ΔΩ⟩ (only the scaling and vertical basis
//    functions have non-zero solid-angle moments).
//  * Local — the seed's one-level idea with the best estimates it allows:
//    the finite chain rule of Refined (2) over f's differences, of which
//    those inside a block come exactly from the start level's details, those
//    between sibling blocks exactly from the parent level's details (the
//    "information from the next coarser level"), and those between blocks of
//    different parents by central differences of the neighbouring sibling
//    differences. The scaling coefficient from the invariant integral.
//  * Refined (default) — the chain rule in exact finite form:
//    (1) f's differences across every pixel boundary, exactly: inside each
//        2×2 block from the details (v and d' separate its two columns, h and
//        d' its two rows), across blocks from the start level's scaling
//        values — information from the coarser levels;
//    (2) g(p₂) − g(p₁) = f(S(p₂)) − f(S(p₁)) as a sum over the source cells
//        the path crosses: between four pixel centres f is bilinear,
//        f₀ + y·dθ + x·dφ + xy·dθφ, so each cell adds terms in f's
//        difference fields alone;
//    (3) the scaling coefficient anchored on one absolute value of f (at the
//        source of g's first pixel) plus g's summed differences.
//    The result equals `spatial`'s bilinear resampling up to float rounding
//    (the rotation report measures it), and pure φ-shifts by whole pixels are
//    exact. The price of exactness is that it reads the coarser levels too —
//    exactly what the seed hoped to avoid; the report times both variants.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "haarcast/core/rotation.h"

namespace haarcast {

struct HaarRotationOptions {
  HaarVariant variant = HaarVariant::Refined;
  int startLevel = -1;  // detail level to start from; −1 = finest (n−1)
};

HaarMap rotateHaar(const HaarMap& f, const EulerYXY& r, const HaarRotationOptions& options = {});

// ---- Three colour channels at once: the per-pixel path ----------------------
//
// A pixel rotates the same slice of its R, G and B tables by one rotation.
// Everything in Refined that depends on the rotation alone is computed once
// and applied to the three channels together:
//  * the source position S(p) = (Φ, Θ) of every working pixel centre, Rᵀp in
//    spherical coordinates (seed eqs. 8–10), from per-level tables of the
//    pixel centres' sines and cosines: one acos and one atan2 per pixel;
//  * step (2)'s walk of each path S(p₁) → S(p₂) over the source cells it
//    crosses (the finite chain rule, seed eqs. 11–13): which cells, and each
//    cell's bilinear weights y₁−y₀, x₁−x₀, x₁y₁−x₀y₀. The three channels'
//    difference fields are read at the same cells in the same pass.
// Per channel remain only the linear parts: step (1) (f's exact differences
// from the details and the start level's scaling values), step (3) (the
// scaling anchor) and the recursive h_t / h_s sums (seed eqs. 14–16), each
// done for the three channels in one loop.
//
// The result is the same as three rotateHaar calls up to double rounding
// (the coefficients are stored as float either way). Faithful and Local take
// the single-channel path, one channel after another.

// Work buffers for rotateHaar3, owned by the caller and kept between calls
// (one per thread): once they have grown to a level's size, a call allocates
// nothing. What they hold between calls means nothing.
struct HaarRotationScratch {
  std::vector<double> scaling, synthesis;  // start-level scaling values of one channel, and work space
  std::vector<double> cells;               // f's differences per source cell, 3 channels
  std::vector<double> points;              // source position of every working pixel centre
  std::vector<double> dTheta, dPhi, dMixed;  // g's difference fields, 3 channels
  std::vector<double> sumsA, sumsB;        // the h_t / h_s recursion, ping-pong
};

// Rotates the three maps f[0..2] (one slice, three channels; all one level) by
// r into out[0..2] (resized to f's level). Throws std::invalid_argument on a
// null map, mixed levels, or a start level finer than the maps' finest.
void rotateHaar3(const std::array<const HaarMap*, 3>& f, const EulerYXY& r, std::array<HaarMap, 3>& out,
                 HaarRotationScratch& scratch, const HaarRotationOptions& options = {});

// The `haar` method for an RGB slice table: owns the three channels' unrotated
// slices (BrdfSliceTable::channelSlices(c)) and rotates one slice of all
// three per call with rotateHaar3. rotate() is const and thread-safe as long
// as each thread passes its own scratch.
class RgbHaarRotator {
 public:
  // Throws std::invalid_argument if a channel is empty, the channels differ in
  // slice count, the slices mix levels, or the start level is too fine.
  explicit RgbHaarRotator(std::array<std::vector<HaarMap>, 3> channelSlices, const HaarRotationOptions& options = {});
  // The haar fields of RotatorOptions (variant, start level).
  RgbHaarRotator(std::array<std::vector<HaarMap>, 3> channelSlices, const RotatorOptions& options);

  std::size_t sliceCount() const { return slices_[0].size(); }
  int level() const { return slices_[0].front().level(); }
  const HaarRotationOptions& options() const { return options_; }

  // out[c] = slice `slice` of channel c rotated by r. Throws std::out_of_range
  // for a slice index ≥ sliceCount().
  void rotate(std::size_t slice, const EulerYXY& r, std::array<HaarMap, 3>& out, HaarRotationScratch& scratch) const;

  // Only the unrotated slices of the three channels, as for SliceRotator.
  std::size_t storedBytes() const;

 private:
  std::array<std::vector<HaarMap>, 3> slices_;
  HaarRotationOptions options_;
};

// ∫ f dω of the map whose coefficients are `f`, from the coefficients alone
// (the solid-angle moments of the scaling and vertical basis functions).
double integralFromCoefficients(const HaarMap& f);

// Step (1) of Refined at the finest start level, on its own: f's exact
// differences across every pixel boundary of its level-n map, from the
// details and the level-(n−1) scaling values. The GPU backend derives them
// once per slice at load time (gpu/rotation_data.h) from this one definition.
struct PixelDifferences {
  int size = 0;               // M
  std::vector<double> theta;  // (M−1)×M, row-major: f(t+1, c) − f(t, c)
  std::vector<double> phi;    // M×M: f(r, c+1) − f(r, c), c+1 wrapping
};
// Throws std::invalid_argument for a level-0 map (it has no boundaries).
PixelDifferences refinedPixelDifferences(const HaarMap& f);

// ⟨ψ, ΔΩ⟩ of the vertical detail of detail level l, block row i, in a level-n
// map: the weight of that coefficient in ∫f dω, with which Faithful anchors
// its scaling coefficient (and the GPU backend packs per level and row).
double verticalDetailMoment(int mapLevel, int l, int i);

}  // namespace haarcast
