// Measured isotropic BRDFs in the MERL format (Matusik, Pfister, Brand,
// McMillan 2003, "A Data-Driven Reflectance Model"; the layout of the MERL
// BRDF database's `.binary` files and its reference reader BRDFRead.cpp).
//
// File layout, little-endian:
//   int32 dims[3] = {90, 90, 180}          θh, θd, φd resolutions
//   double red[1458000], green[…], blue[…]  cell (iθh, iθd, iφd) at
//                                            iφd + 180·(iθd + 90·iθh)
// A stored value is ρ divided by the channel scale (1/1500, 1.15/1500,
// 1.66/1500); a negative value marks a cell below the horizon (no data).
//
// Coordinates are Rusinkiewicz's half/difference angles (1998): θh is the
// half vector's elevation, (θd, φd) the incoming direction seen from the half
// vector, φd measured from the plane of the normal and the half vector. The
// cells are
//   iθh = ⌊√(θh/(π/2))·90⌋   (non-linear: finer near the specular peak)
//   iθd = ⌊θd/(π/2)·90⌋,  iφd = ⌊φd/π·180⌋, φd folded into [0, π)
// by reciprocity (φd and φd + π are the same pair of directions, swapped), all
// clamped to the table. Taking the floor of the continuous index picks the
// cell whose centre (index + ½) is nearest in index space. That is how BRDFRead.cpp
// looks values up (nearest cell, no interpolation), and it is where the cell
// values of the synthesised files in ../shared/data were sampled.
//
// Frames. MERL's code puts the normal on +Z with φ from +X toward +Y;
// haarcast's local frame puts it on +Y with φ from +Z toward +X (DESIGN.md
// "Directions"). A haarcast local vector (x, y, z) is the MERL vector
// (z, x, y): a proper rotation (it keeps handedness, so φd keeps its sign)
// that maps haarcast's (θ, φ) to MERL's (θ, φ) unchanged.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec3.hpp>

#include "haarcast/core/brdf.h"

namespace haarcast::io {

inline constexpr int kMerlThetaHalfRes = 90;
inline constexpr int kMerlThetaDiffRes = 90;
inline constexpr int kMerlPhiDiffRes = 180;  // over [0, π): BRDFRead.cpp's BRDF_SAMPLING_RES_PHI_D / 2
inline constexpr std::size_t kMerlCells =
    static_cast<std::size_t>(kMerlThetaHalfRes) * kMerlThetaDiffRes * kMerlPhiDiffRes;  // 1,458,000
// 12-byte header and three channels of doubles: 34,992,012 bytes.
inline constexpr std::size_t kMerlFileBytes = 3 * sizeof(std::int32_t) + 3 * kMerlCells * sizeof(double);
// ρ = stored value × scale, per channel (BRDFRead.cpp's RED/GREEN/BLUE_SCALE).
inline constexpr double kMerlScale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};

// Rusinkiewicz coordinates of a pair of haarcast local directions (unit, +Y =
// normal), computed as BRDFRead.cpp's std_coords_to_half_diff_coords does
// after the frame change above, with the difference vector taken from ωᵢ.
// θh, θd ∈ [0, π]; φd ∈ (−π, π] (not yet folded).
struct HalfDiff {
  double thetaHalf;
  double thetaDiff;
  double phiDiff;
};
HalfDiff halfDiffCoordinates(const glm::dvec3& wi, const glm::dvec3& wo);

// The cell indices of the file comment; out-of-range angles clamp.
int merlThetaHalfIndex(double thetaHalf);
int merlThetaDiffIndex(double thetaDiff);
int merlPhiDiffIndex(double phiDiff);  // folds φd < 0 by + π first
// Position of cell (iθh, iθd, iφd) within one channel of the file.
inline std::size_t merlCellIndex(int thetaHalfIndex, int thetaDiffIndex, int phiDiffIndex) {
  return static_cast<std::size_t>(phiDiffIndex) +
         static_cast<std::size_t>(kMerlPhiDiffRes) *
             (static_cast<std::size_t>(thetaDiffIndex) +
              static_cast<std::size_t>(kMerlThetaDiffRes) * static_cast<std::size_t>(thetaHalfIndex));
}

class MerlBrdf : public Brdf {
 public:
  // rgb holds 3·kMerlCells values of ρ (already scaled), interleaved per cell
  // ([cell·3 + channel], cell = merlCellIndex(…)); negative = no data. Throws
  // std::invalid_argument on a wrong size or a non-finite value.
  // repairedCells only records what the loader did (see repairedCells()).
  MerlBrdf(std::string name, std::vector<float> rgb, std::size_t repairedCells = 0);

  // Nearest cell (see the file comment); a channel whose cell has no data,
  // and any direction at or below the horizon, gives 0.
  glm::dvec3 evaluate(const glm::dvec3& wi, const glm::dvec3& wo) const override;
  std::string name() const override { return name_; }

  // The stored ρ of a cell, negative where it has no data.
  glm::dvec3 cell(int thetaHalfIndex, int thetaDiffIndex, int phiDiffIndex) const;

  // How many (cell, channel) values the loader repaired (MerlLoadOptions).
  std::size_t repairedCells() const { return repairedCells_; }

 private:
  std::string name_;
  std::size_t repairedCells_ = 0;
  // Floats, not the file's doubles: half the memory (17.5 MB), and the slice
  // tables the BRDF feeds are floats anyway (7 significant digits against
  // the measurement's few percent).
  std::vector<float> rgb_;
};

struct MerlLoadOptions {
  // A non-finite value is a defect of the file, so by default it is refused.
  // With repair on, each non-finite cell takes the mean of the finite cells of
  // its (channel, θh, θd) row over φd; a row with none is still refused. This
  // is the right value where the defects seen so far are: at θh index 0
  // (θh < 0.011°), where the half vector is the normal, φd is degenerate and
  // an isotropic BRDF cannot depend on it. (../shared/data's
  // chrome-steel-sgd.binary has 247 NaN cells per channel there.)
  bool repairNonFinite = false;
};

// Reads and validates a MERL `.binary` file: its size must be exactly
// kMerlFileBytes, its dims exactly 90 90 180, every value finite (see
// MerlLoadOptions). Throws std::runtime_error naming the path and the problem.
// name() is the file's stem (`alum-bronze` for `alum-bronze.binary`).
std::unique_ptr<Brdf> loadMerl(const std::string& path, const MerlLoadOptions& options = {});
// The same, typed, for callers that want cell() or repairedCells().
std::unique_ptr<MerlBrdf> loadMerlBrdf(const std::string& path, const MerlLoadOptions& options = {});
// The same from a file's bytes in memory; `name` names the BRDF and the
// errors. A pure function over bytes, so it can be fuzzed.
std::unique_ptr<MerlBrdf> parseMerlBrdf(std::string_view bytes, const std::string& name,
                                        const MerlLoadOptions& options = {});

}  // namespace haarcast::io
