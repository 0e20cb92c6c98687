// `fused` (fused.h): what is prepared once, per frame and per pixel, around
// the SIMD pass of fused_kernel.cpp.
#include "haarcast/core/fused.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "fused_kernel.h"
#include "haarcast/core/check.h"
#include "haarcast/core/shared_cells.h"

namespace haarcast {
namespace {

// One synthesis step of the inverse Haar transform (haar.cpp's, in float):
// the top-left n×n block of `a` (row stride `stride`) from s, h, v, d quadrants
// to the n×n values one level finer.
void synthesisStep(float* a, int stride, int n, float* scratch) {
  const int half = n / 2;
  for (int i = 0; i < half; ++i) {
    for (int j = 0; j < half; ++j) {
      const float s = a[i * stride + j], h = a[i * stride + j + half];
      const float v = a[(i + half) * stride + j], d = a[(i + half) * stride + j + half];
      scratch[(2 * i) * n + 2 * j] = 0.5f * (s + h + v + d);
      scratch[(2 * i) * n + 2 * j + 1] = 0.5f * (s - h + v - d);
      scratch[(2 * i + 1) * n + 2 * j] = 0.5f * (s + h - v - d);
      scratch[(2 * i + 1) * n + 2 * j + 1] = 0.5f * (s - h - v + d);
    }
  }
  for (int r = 0; r < n; ++r) std::copy_n(scratch + r * n, n, a + r * stride);
}

// Dense coefficients (quadrant layout) → pixel values, in place.
void synthesizeInPlace(std::span<float> coefficients, int level, std::vector<float>& scratch) {
  const int m = mapSize(level);
  scratch.resize(coefficients.size());
  for (int n = 2; n <= m; n *= 2) synthesisStep(coefficients.data(), m, n, scratch.data());
}

void checkSameLevel(int level, int expected, const char* what) {
  if (level != expected) {
    throw std::invalid_argument(std::string("fused: ") + what + " is at level " + std::to_string(level) +
                                ", the slices at level " + std::to_string(expected));
  }
}

}  // namespace

void checkFusedLevel(int level) {
  if (level < static_cast<int>(shared::kMinLevel) || level > static_cast<int>(shared::kFusedMaxLevel)) {
    throw std::invalid_argument("fused: level " + std::to_string(level) + " is outside " +
                                std::to_string(shared::kMinLevel) + ".." + std::to_string(shared::kFusedMaxLevel));
  }
}

namespace detail {
const PixelDirections& pixelDirections(int level) {
  struct Table {
    std::vector<float> x, y, z, solidAngle;
    PixelDirections view;
  };
  // Built once for every level `fused` takes (thread-safe static initialisation).
  static const std::array<Table, shared::kFusedMaxLevel + 1> tables = [] {
    std::array<Table, shared::kFusedMaxLevel + 1> t;
    for (int l = 0; l <= static_cast<int>(shared::kFusedMaxLevel); ++l) {
      const int m = mapSize(l);
      Table& table = t[static_cast<std::size_t>(l)];
      for (int i = 0; i < m; ++i) {
        const float omega = static_cast<float>(pixelSolidAngle(l, i));
        for (int j = 0; j < m; ++j) {
          table.solidAngle.push_back(omega);
          const glm::dvec3 dir = sphericalToDirection(rowTheta(l, i), colPhi(l, j));
          table.x.push_back(static_cast<float>(dir.x));
          table.y.push_back(static_cast<float>(dir.y));
          table.z.push_back(static_cast<float>(dir.z));
        }
      }
      table.view = {table.x.data(), table.y.data(), table.z.data(), table.solidAngle.data()};
    }
    return t;
  }();
  return tables.at(static_cast<std::size_t>(level)).view;
}
}  // namespace detail

namespace {

// Every slice of a table in pixel form: (t, row, col) at ((t·M + row)·M + col)·4.
std::vector<float> sliceTexels(const BrdfSliceTable& table) {
  const std::size_t n = static_cast<std::size_t>(mapSize(table.level())) * static_cast<std::size_t>(mapSize(table.level()));
  std::vector<float> texels(static_cast<std::size_t>(table.thetaSamples()) * n * shared::kTexelFloats, 0.0f);
  for (int t = 0; t < table.thetaSamples(); ++t) {
    float* dst = texels.data() + static_cast<std::size_t>(t) * n * shared::kTexelFloats;
    for (int c = 0; c < BrdfSliceTable::kChannels; ++c) {
      const SphereMap pixels = inverseHaar(table.slice(c, t));
      const std::span<const float> values = pixels.values();
      for (std::size_t p = 0; p < n; ++p) dst[p * shared::kTexelFloats + static_cast<std::size_t>(c)] = values[p];
    }
  }
  return texels;
}

// Each texel's mean turned into its centre's value (shared::pointFromMean),
// the same layout.
std::vector<float> pointValues(const std::vector<float>& means, int level, int thetaSamples) {
  const int m = mapSize(level);
  const std::size_t n = static_cast<std::size_t>(m) * static_cast<std::size_t>(m);
  std::vector<float> points(means.size(), 0.0f);
  for (int t = 0; t < thetaSamples; ++t) {
    const float* mean = means.data() + static_cast<std::size_t>(t) * n * shared::kTexelFloats;
    float* point = points.data() + static_cast<std::size_t>(t) * n * shared::kTexelFloats;
    auto at = [&](int row, int col, int c) {
      return mean[static_cast<std::size_t>(row * m + (col & (m - 1))) * shared::kTexelFloats + static_cast<std::size_t>(c)];
    };
    for (int row = 0; row < m; ++row) {
      const int up = std::max(row - 1, 0), down = std::min(row + 1, m - 1);
      for (int col = 0; col < m; ++col) {
        for (int c = 0; c < BrdfSliceTable::kChannels; ++c) {
          point[static_cast<std::size_t>(row * m + col) * shared::kTexelFloats + static_cast<std::size_t>(c)] =
              shared::pointFromMean(at(row, col, c), at(up, col, c), at(down, col, c), at(row, col - 1, c), at(row, col + 1, c));
        }
      }
    }
  }
  return points;
}

}  // namespace

PixelSlices PixelSlices::synthesize(const BrdfSliceTable& table, const BrdfSliceTable* pointTable, bool detailMaps) {
  checkFusedLevel(table.level());
  if (pointTable) {
    checkFusedLevel(pointTable->level());
    HC_CHECK_LE(table.level(), pointTable->level());
    HC_CHECK_EQ(pointTable->thetaSamples(), table.thetaSamples());
  }
  PixelSlices out;
  out.level_ = table.level();
  out.pointLevel_ = pointTable ? pointTable->level() : table.level();
  out.thetaSamples_ = table.thetaSamples();
  out.texels_ = sliceTexels(table);
  const int m = mapSize(out.level_);
  const std::size_t n = static_cast<std::size_t>(m) * static_cast<std::size_t>(m);
  out.energy_.assign(static_cast<std::size_t>(out.thetaSamples_), {});
  for (int t = 0; t < out.thetaSamples_; ++t) {
    const float* texels = out.texels_.data() + static_cast<std::size_t>(t) * n * shared::kTexelFloats;
    for (std::size_t c = 0; c < static_cast<std::size_t>(BrdfSliceTable::kChannels); ++c) {
      double energy = 0.0;  // SphereMap::integral's sum: rows, then their solid angles
      for (int row = 0; row < m; ++row) {
        double sum = 0.0;
        for (int col = 0; col < m; ++col) {
          const float v = texels[static_cast<std::size_t>(row * m + col) * shared::kTexelFloats + c];
          if (v != 0.0f) out.lastNonZeroRow_ = std::max(out.lastNonZeroRow_, row);
          sum += v;
        }
        energy += sum * pixelSolidAngle(out.level_, row);
      }
      out.energy_[static_cast<std::size_t>(t)][c] = static_cast<float>(energy);
    }
  }
  // The point lights' lookup reads a finer table where one is given: one
  // Catmull-Rom read a light, so its texels cost memory only.
  out.pointTexels_ = pointValues(pointTable ? sliceTexels(*pointTable) : out.texels_, out.pointLevel_, out.thetaSamples_);
  if (detailMaps && out.level_ >= static_cast<int>(shared::kCellMinLevel)) {
    for (int t = 0; t < out.thetaSamples_; ++t) {
      const std::vector<float> d = sliceDetail(out.slice(t), out.level_, out.energy_[static_cast<std::size_t>(t)].data());
      out.detail_.insert(out.detail_.end(), d.begin(), d.end());
    }
  }
  return out;
}

const float* PixelSlices::detail(int t) const {
  if (detail_.empty()) return nullptr;
  if (t < 0 || t >= thetaSamples_) {
    throw std::out_of_range("PixelSlices: detail map " + std::to_string(t) + " of " + std::to_string(thetaSamples_));
  }
  return detail_.data() + detail_.size() / static_cast<std::size_t>(thetaSamples_) * static_cast<std::size_t>(t);
}

const float* PixelSlices::pointSlice(int t) const {
  if (t < 0 || t >= thetaSamples_) {
    throw std::out_of_range("PixelSlices: point slice " + std::to_string(t) + " of " + std::to_string(thetaSamples_));
  }
  const std::size_t n = static_cast<std::size_t>(mapSize(pointLevel_)) * static_cast<std::size_t>(mapSize(pointLevel_));
  return pointTexels_.data() + static_cast<std::size_t>(t) * n * shared::kTexelFloats;
}

const float* PixelSlices::slice(int t) const {
  if (t < 0 || t >= thetaSamples_) {
    throw std::out_of_range("PixelSlices: slice " + std::to_string(t) + " of " + std::to_string(thetaSamples_));
  }
  const std::size_t n = static_cast<std::size_t>(mapSize(level_)) * static_cast<std::size_t>(mapSize(level_));
  return texels_.data() + static_cast<std::size_t>(t) * n * shared::kTexelFloats;
}

FusedLight FusedLight::synthesize(const std::array<SparseHaar, 3>& light) {
  FusedLight out;
  out.level = light[0].level;
  checkFusedLevel(out.level);
  const std::size_t n = static_cast<std::size_t>(mapSize(out.level)) * static_cast<std::size_t>(mapSize(out.level));
  out.planes.assign(3 * n, 0.0f);
  std::vector<float> scratch;
  for (std::size_t c = 0; c < 3; ++c) {
    checkSameLevel(light[c].level, out.level, "a light channel");
    const std::span<float> plane(out.planes.data() + c * n, n);
    for (std::size_t e = 0; e < light[c].size(); ++e) plane[light[c].index[e]] = light[c].value[e];
    synthesizeInPlace(plane, out.level, scratch);
  }
  return out;
}

FusedLight FusedLight::fromWeightedMaps(const std::array<SphereMap, 3>& weighted, float sumTolerance) {
  FusedLight out;
  out.level = weighted[0].level();
  checkFusedLevel(out.level);
  const std::size_t n = static_cast<std::size_t>(mapSize(out.level)) * static_cast<std::size_t>(mapSize(out.level));
  out.planes.resize(3 * n);
  for (std::size_t c = 0; c < 3; ++c) {
    checkSameLevel(weighted[c].level(), out.level, "a light channel");
    std::copy(weighted[c].values().begin(), weighted[c].values().end(), out.planes.begin() + static_cast<std::ptrdiff_t>(c * n));
  }
  if (!(sumTolerance >= 0.0f)) throw std::invalid_argument("fused: the sum tolerance must be ≥ 0");
  out.sumTolerance = sumTolerance;
  if (shared::sumsByCells(static_cast<shared::uint>(out.level), sumTolerance)) out.cells = CellLight::fromPlanes(out.level, out.planes);
  return out;
}

namespace {

// ρ as the pass reads it: one slice, or the blend of two (linear, so
// blending the texels once equals blending the two sums). Rows past
// lastNonZeroRow are zero in every slice, so only the rows above are
// blended; the buffer's rows below are kept zero (they may hold another
// object's rows from an earlier pixel).
const float* blendedSlice(const PixelSlices& slices, const shared::SliceBlend& blend, FusedScratch& scratch) {
  const int level = slices.level();
  const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  const float* slice = slices.slice(static_cast<int>(blend.first));
  if (blend.weight == 0.0f || blend.second == blend.first) return slice;
  const float* other = slices.slice(static_cast<int>(blend.second));
  const std::size_t rowFloats = static_cast<std::size_t>(mapSize(level)) * shared::kTexelFloats;
  const std::size_t rows = static_cast<std::size_t>(slices.lastNonZeroRow() + 1);
  if (scratch.blended.size() != n * shared::kTexelFloats) {
    scratch.blended.assign(n * shared::kTexelFloats, 0.0f);
    scratch.blendedRows = 0;
  }
  if (scratch.blendedRows > rows) {
    std::fill(scratch.blended.begin() + static_cast<std::ptrdiff_t>(rows * rowFloats),
              scratch.blended.begin() + static_cast<std::ptrdiff_t>(scratch.blendedRows * rowFloats), 0.0f);
  }
  scratch.blendedRows = rows;
  const float w = blend.weight;
  for (std::size_t k = 0; k < rows * rowFloats; ++k) scratch.blended[k] = slice[k] + w * (other[k] - slice[k]);
  return scratch.blended.data();
}

// γ as a column offset of a level's map: source column = φ'·M/2π − (γ·M/2π
// + ½); the offset's whole part is applied to the integer column, its
// fraction to the float coordinate.
struct ColumnOffset {
  int shift = 0;
  float fraction = 0.0f;
};
ColumnOffset columnOffset(double gamma, int level) {
  const int m = mapSize(level);
  double offset = gamma / kTwoPi * m + 0.5;
  offset -= std::floor(offset / m) * m;  // [0, M): whole turns change nothing
  const double whole = std::floor(offset);
  return {static_cast<int>(whole), static_cast<float>(offset - whole)};
}

// The rotation's part of a pass: Rᵀ's angles, and γ as a column offset.
void setRotation(detail::FusedPass& pass, const EulerYXY& r) {
  pass.cosAlpha = static_cast<float>(std::cos(r.alpha));
  pass.sinAlpha = static_cast<float>(std::sin(r.alpha));
  pass.cosBeta = static_cast<float>(std::cos(r.beta));
  pass.sinBeta = static_cast<float>(std::sin(r.beta));
  const ColumnOffset column = columnOffset(r.gamma, pass.level);
  pass.columnShift = column.shift;
  pass.columnFraction = column.fraction;
}

detail::FusedPass makePass(const PixelSlices& slices, const float* slice, const EulerYXY& r) {
  detail::FusedPass pass;
  pass.level = slices.level();
  pass.slice = slice;
  pass.directions = detail::pixelDirections(pass.level);
  setRotation(pass, r);
  // A direction whose source row is beyond lastNonZeroRow + 1 reads only zero
  // texels (both bilinear rows are zero); one more row of margin absorbs the
  // float rounding of θ'.
  const int m = mapSize(pass.level);
  const int cutRow = slices.lastNonZeroRow() + 2;
  pass.skipBelowY = cutRow < m ? static_cast<float>(std::cos(cutRow * kPi / m)) : -2.0f;
  const shared::uvec2 rows = shared::passRows(static_cast<shared::uint>(m), pass.cosBeta, pass.skipBelowY);
  pass.firstRow = static_cast<int>(rows.x);
  pass.endRow = static_cast<int>(rows.y);
  return pass;
}

// The pass, with the lobe's energy put back: the M² map directions sample
// ρ(Rᵀω) at points, so a lobe about as narrow as a texel is over- or
// under-counted depending on where it falls between them — rings as R turns
// across a surface. Σ ΔΩ·ρ(Rᵀω) measures that count in the same pass, and
// ∫ρ of the slice is what it should be.
std::array<float, 3> energyRatio(const float sums[6], const std::array<float, 3>& energy) {
  std::array<float, 3> out{};
  for (std::size_t c = 0; c < 3; ++c) out[c] = sums[3 + c] > 0.0f ? sums[c] * (energy[c] / sums[3 + c]) : sums[c];
  return out;
}
std::array<float, 3> energyKept(const detail::FusedPass& pass, const std::array<float, 3>& energy) {
  float sums[6] = {};
  detail::fusedSample(pass, sums);
  return energyRatio(sums, energy);
}

// ∫ρ_c of the slice between the blend's two slices.
std::array<float, 3> sliceEnergy(const PixelSlices& slices, const shared::SliceBlend& blend) {
  const std::array<float, 3>& e0 = slices.energy(static_cast<int>(blend.first));
  const std::array<float, 3>& e1 = slices.energy(static_cast<int>(blend.second));
  std::array<float, 3> out{};
  for (std::size_t c = 0; c < 3; ++c) out[c] = e0[c] + blend.weight * (e1[c] - e0[c]);
  return out;
}

// The core of the lobe path in the pass's frame: the lobe's axis, local
// (0, cos θ, −sin θ) at φ' = π, is at φ = π + γ before R_y(−γ).
void setCore(detail::FusedPass& pass, const EulerYXY& r, float axisTheta, float coreAngle) {
  const float s = std::sin(axisTheta);
  pass.axisX = -s * static_cast<float>(std::sin(r.gamma));
  pass.axisY = std::cos(axisTheta);
  pass.axisZ = -s * static_cast<float>(std::cos(r.gamma));
  pass.coreCos = std::cos(coreAngle);
}

}  // namespace

std::array<float, 3> fusedShade(const PixelSlices& slices, const shared::SliceBlend& blend, const EulerYXY& r,
                                const FusedLight& light, std::span<const WeightedBits> visibility,
                                std::span<const FusedPointLight> lights, std::uint32_t visibleLights,
                                FusedScratch& scratch, const LobePath* lobe, const std::array<float, 3>* hidden,
                                FusedSum* sum) {
  const int level = slices.level();
  scratch.passDirections = 0;
  if (lobe && lobe->coreAngle >= static_cast<float>(kPi)) return lobeShade(*lobe, blend, r, visibleLights);
  checkSameLevel(light.level, level, "the light");
  const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  // Three vertices' bits are blended in the pass; otherwise (another count,
  // or vectors wider than a word) here, into V.
  static const bool bitsInPass = detail::fusedLanes() <= 32;
  const bool inPass = bitsInPass && visibility.size() == 3;
  const bool given = sum && sum->given;
  if (!inPass && !given) {
    scratch.visibility.resize(n);
    blendVisibility(visibility, level, scratch.visibility);
  }

  // Given the sum, the pass is only its turn (pointRho, the core's cone).
  detail::FusedPass pass = makePass(slices, given ? nullptr : blendedSlice(slices, blend, scratch), r);
  scratch.passDirections = given ? 0 : static_cast<std::size_t>(pass.endRow - pass.firstRow) * static_cast<std::size_t>(mapSize(level));
  pass.light = light.planes.data();
  if (inPass) {
    pass.visibility = nullptr;
    for (std::size_t v = 0; v < 3; ++v) {
      pass.bits[v] = visibility[v].words;
      pass.bitWeight[v] = visibility[v].weight;
    }
  } else {
    pass.visibility = scratch.visibility.data();
  }
  std::array<float, 3> energy = sliceEnergy(slices, blend);
  shared::SliceLobe core{};
  if (lobe) {
    // The pass takes the lobe outside the core, and its energy, E − E_core.
    core = shared::blendLobes(lobe->lobes[blend.first], lobe->lobes[blend.second], blend.weight);
    setCore(pass, r, core.energy.w, lobe->coreAngle);
    for (std::size_t c = 0; c < 3; ++c) energy[c] = std::max(0.0f, core.energy[static_cast<int>(c)] - core.core[static_cast<int>(c)]);
  }
  std::array<float, 3> out{};
  if (given) {
    out = sum->value;
    scratch.cellCounts = {};
  } else if (inPass && light.sumsByCells() && slices.detail(0)) {
    // By cells (shared_cells.h): at one direction where the slice is
    // smooth, the rest direction by direction.
    detail::FusedCellPass cells;
    cells.pass = pass;
    cells.cells = &cellDirections(level);
    cells.light = &light.cells;
    cells.detail[0] = slices.detail(static_cast<int>(blend.first));
    cells.detail[1] = slices.detail(static_cast<int>(blend.weight != 0.0f ? blend.second : blend.first));
    cells.tolerance = light.sumTolerance;
    cells.cellMaskWords = cellMaskWords(level);
    for (std::size_t v = 0; v < 3; ++v) {
      if (visibility[v].cells) {
        cells.cellMasks[v] = visibility[v].cells;
        continue;
      }
      scratch.cells.masks.resize(6 * cells.cellMaskWords);
      std::uint32_t* masks = scratch.cells.masks.data() + 2 * v * cells.cellMaskWords;
      cellMasks(visibility[v].words, level, masks);
      cells.cellMasks[v] = masks;
    }
    const shared::uint m = static_cast<shared::uint>(mapSize(level));
    if (lobe) cells.coreCellCos = std::cos(std::min(lobe->coreAngle + shared::cellReach(m), static_cast<float>(kPi)));
    cells.reachCut = shared::cellReachCut(m, pass.skipBelowY);
    float sums[6] = {};
    scratch.cellCounts = {};
    detail::fusedSampleCells(cells, scratch.cells, sums, scratch.cellCounts);
    scratch.passDirections = scratch.cellCounts.coarse + shared::kCellDirections * scratch.cellCounts.fine;
    out = energyRatio(sums, energy);
  } else {
    out = energyKept(pass, energy);
  }
  if (!given) {
    // The sky other objects hide, taken off before the sum is kept: what a
    // pixel's neighbours give it is their sum less their hidden sky, which
    // changes as smoothly across a surface (core/shared_smooth.h), so a
    // pixel that takes its parents' needs no hidden-sky rays of its own.
    if (hidden) {
      for (std::size_t c = 0; c < 3; ++c) out[c] -= (*hidden)[c] * energy[c] / static_cast<float>(kPi);
    }
    if (sum) sum->value = out;
  }
  // The point lights it sees: ρ at each one's direction, a vector of them at
  // a time (point_rho_kernel.cpp), at the point slices' level.
  HC_CHECK_LE(lights.size(), std::size_t{shared::kMaxPointLights});
  std::size_t seen = 0;
  for (std::size_t k = 0; k < lights.size(); ++k) {
    if (((visibleLights >> k) & 1u) == 0) continue;
    scratch.lightX[seen] = lights[k].direction.x;
    scratch.lightY[seen] = lights[k].direction.y;
    scratch.lightZ[seen] = lights[k].direction.z;
    scratch.lightIndex[seen++] = static_cast<std::uint32_t>(k);
  }
  if (seen > 0) {
    const ColumnOffset pointColumn = columnOffset(r.gamma, slices.pointLevel());
    detail::PointRhoPass points;
    points.pass = &pass;
    points.level = slices.pointLevel();
    points.columnShift = pointColumn.shift;
    points.columnFraction = pointColumn.fraction;
    points.first = slices.pointSlice(static_cast<int>(blend.first));
    points.second = blend.weight != 0.0f ? slices.pointSlice(static_cast<int>(blend.second)) : points.first;
    points.weight = blend.weight;
    detail::pointRho(points, scratch.lightX.data(), scratch.lightY.data(), scratch.lightZ.data(), seen, scratch.lightRho.data());
    for (std::size_t j = 0; j < seen; ++j)
      for (std::size_t c = 0; c < 3; ++c) out[c] += lights[scratch.lightIndex[j]].power[c] * scratch.lightRho[c * kPointLightLanes + j];
  }
  // The hidden sky taken off may leave less than nothing; the sum is kept ≥ 0.
  for (std::size_t c = 0; c < 3; ++c) out[c] = std::max(0.0f, out[c]);
  if (lobe) {
    const std::array<float, 3> inCore = lobeShade(*lobe, blend, r, visibleLights);
    for (std::size_t c = 0; c < 3; ++c) out[c] += inCore[c];
  }
  return out;
}

std::array<float, 3> fusedShade(const PixelSlices& slices, const shared::SliceBlend& blend, const EulerYXY& r,
                                const FusedLight& light, std::span<const WeightedVisibility> visibility,
                                FusedScratch& scratch) {
  const int level = slices.level();
  checkSameLevel(light.level, level, "the light");
  const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));

  // V: the vertices' lists merged into one weighted coefficient list (the
  // product is linear in V), then synthesised once.
  scratch.visibility.assign(n, 0.0f);
  for (const WeightedVisibility& v : visibility) {
    checkSameLevel(v.list->level, level, "a visibility list");
    for (std::size_t e = 0; e < v.list->size(); ++e) scratch.visibility[v.list->index[e]] += v.weight * v.list->value[e];
  }
  synthesizeInPlace(scratch.visibility, level, scratch.synthesis);

  detail::FusedPass pass = makePass(slices, blendedSlice(slices, blend, scratch), r);
  scratch.passDirections = static_cast<std::size_t>(pass.endRow - pass.firstRow) * static_cast<std::size_t>(mapSize(level));
  pass.light = light.planes.data();
  pass.visibility = scratch.visibility.data();
  return energyKept(pass, sliceEnergy(slices, blend));
}

std::array<float, 3> lobeShade(const LobePath& path, const shared::SliceBlend& blend, const EulerYXY& r,
                               std::uint32_t word) {
  if ((word & shared::kLobeSeenBit) == 0u) return {0.0f, 0.0f, 0.0f};
  const shared::SliceLobe lobe = shared::blendLobes(path.lobes[blend.first], path.lobes[blend.second], blend.weight);
  // The axis in the slice's frame (φ = π side) and two directions across
  // it, turned by R into the object's frame, then into the light's.
  const float c = std::cos(lobe.energy.w), s = std::sin(lobe.energy.w);
  const glm::mat3 toLight = path.toLight * glm::mat3(rotationMatrix(r));
  const glm::vec3 axis = toLight * glm::vec3(0.0f, c, -s);
  const glm::vec3 u = toLight * glm::vec3(1.0f, 0.0f, 0.0f);
  const glm::vec3 v = toLight * glm::vec3(0.0f, -s, -c);
  const glm::vec3 light = path.light->lobe(lobe, axis, u, v);
  return {lobe.core.r * light.r, lobe.core.g * light.g, lobe.core.b * light.b};
}

std::string fusedTargetName() { return detail::fusedTarget(); }

std::size_t fusedPixelBytes(int level, bool blended, std::size_t visibilityBytes) {
  const std::size_t n = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  const std::size_t slice = n * shared::kTexelFloats * sizeof(float);
  return slice * (blended ? 2 : 1) + 3 * n * sizeof(float) + visibilityBytes;
}

}  // namespace haarcast
