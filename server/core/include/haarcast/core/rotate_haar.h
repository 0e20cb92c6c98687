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

#include <vector>

#include "haarcast/core/rotation.h"

namespace haarcast {

struct HaarRotationOptions {
  HaarVariant variant = HaarVariant::Refined;
  int startLevel = -1;  // detail level to start from; −1 = finest (n−1)
};

HaarMap rotateHaar(const HaarMap& f, const EulerYXY& r, const HaarRotationOptions& options = {});

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
