// The adaptive sum's inputs (fused_cells.h): directions and light in cell
// order, and the slices' detail maps.
#include "haarcast/core/fused_cells.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "fused_kernel.h"
#include "haarcast/core/check.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/core/visibility_bits.h"

namespace haarcast {
namespace {

static_assert(shared::kCellDetailStride ==
              (1u << (2u * (shared::kFusedMaxLevel - 2u))));  // (M/4)² at the finest level `fused` takes

void checkCellLevel(int level) {
  if (level < static_cast<int>(shared::kCellMinLevel) || level > static_cast<int>(shared::kFusedMaxLevel)) {
    throw std::invalid_argument("fused cells: level " + std::to_string(level) + " is outside " +
                                std::to_string(shared::kCellMinLevel) + ".." + std::to_string(shared::kFusedMaxLevel));
  }
}

std::size_t cellCount(int level) {
  const std::size_t across = static_cast<std::size_t>(mapSize(level)) / shared::kCellSide;
  return across * across;
}

}  // namespace

const CellDirections& cellDirections(int level) {
  checkCellLevel(level);
  static const std::array<CellDirections, shared::kFusedMaxLevel + 1> tables = [] {
    std::array<CellDirections, shared::kFusedMaxLevel + 1> t;
    for (int l = static_cast<int>(shared::kCellMinLevel); l <= static_cast<int>(shared::kFusedMaxLevel); ++l) {
      const detail::PixelDirections& rowMajor = detail::pixelDirections(l);
      const std::uint32_t m = static_cast<std::uint32_t>(mapSize(l));
      const std::size_t cells = cellCount(l);
      CellDirections& c = t[static_cast<std::size_t>(l)];
      for (auto* v : {&c.centreX, &c.centreY, &c.centreZ, &c.cellSolidAngle}) v->assign(cells + kCellPadding, 0.0f);
      for (std::size_t q = 0; q < cells; ++q) {
        glm::dvec3 centre(0.0);
        double omega = 0.0;
        for (std::uint32_t k = 0; k < shared::kCellDirections; ++k) {
          const std::uint32_t i = shared::cellDirection(m, static_cast<std::uint32_t>(q), k);
          c.x.push_back(rowMajor.x[i]);
          c.y.push_back(rowMajor.y[i]);
          c.z.push_back(rowMajor.z[i]);
          c.solidAngle.push_back(rowMajor.solidAngle[i]);
          centre += static_cast<double>(rowMajor.solidAngle[i]) * glm::dvec3(rowMajor.x[i], rowMajor.y[i], rowMajor.z[i]);
          omega += rowMajor.solidAngle[i];
        }
        centre = glm::normalize(centre);
        c.centreX[q] = static_cast<float>(centre.x);
        c.centreY[q] = static_cast<float>(centre.y);
        c.centreZ[q] = static_cast<float>(centre.z);
        c.cellSolidAngle[q] = static_cast<float>(omega);
      }
    }
    return t;
  }();
  return tables[static_cast<std::size_t>(level)];
}

CellLight CellLight::fromPlanes(int level, std::span<const float> rowMajorPlanes) {
  const CellDirections& dirs = cellDirections(level);
  const std::uint32_t m = static_cast<std::uint32_t>(mapSize(level));
  const std::size_t n = static_cast<std::size_t>(m) * m, cells = cellCount(level);
  HC_CHECK_EQ(rowMajorPlanes.size(), 3 * n);
  const detail::PixelDirections& rowMajor = detail::pixelDirections(level);
  CellLight out;
  out.level = level;
  out.stride = cells + kCellPadding;
  out.planes.assign(3 * n, 0.0f);
  out.power.assign(3 * out.stride, 0.0f);
  for (auto* v : {&out.centroidX, &out.centroidY, &out.centroidZ}) v->assign(out.stride, 0.0f);
  for (std::size_t q = 0; q < cells; ++q) {
    glm::dvec3 centroid(0.0);
    for (std::uint32_t k = 0; k < shared::kCellDirections; ++k) {
      const std::size_t i = shared::cellDirection(m, static_cast<std::uint32_t>(q), k);
      double weight = 0.0;
      for (std::size_t c = 0; c < 3; ++c) {
        const float l = rowMajorPlanes[c * n + i];
        out.planes[c * n + q * shared::kCellDirections + k] = l;
        out.power[c * out.stride + q] += l;
        weight += l;
      }
      centroid += weight * glm::dvec3(rowMajor.x[i], rowMajor.y[i], rowMajor.z[i]);
    }
    const double length = glm::length(centroid);
    // A black cell (or one whose light cancels, which L ≥ 0 never does) sits at its centre.
    const glm::dvec3 at = length > 0.0 ? centroid / length : glm::dvec3(dirs.centreX[q], dirs.centreY[q], dirs.centreZ[q]);
    out.centroidX[q] = static_cast<float>(at.x);
    out.centroidY[q] = static_cast<float>(at.y);
    out.centroidZ[q] = static_cast<float>(at.z);
  }
  return out;
}

std::size_t cellMaskWords(int level) {
  checkCellLevel(level);
  return cellCount(level) / 32 + 1;
}

void cellMasks(const std::uint32_t* words, int level, std::uint32_t* out) {
  const std::size_t setWords = cellMaskWords(level);
  const std::uint32_t m = static_cast<std::uint32_t>(mapSize(level));
  std::uint32_t* whole = out;
  std::uint32_t* any = out + setWords;
  std::fill(out, out + 2 * setWords, 0u);
  for (std::uint32_t q = 0; q < cellCount(level); ++q) {
    const std::uint32_t bits = shared::cellBits(words[shared::cellWordIndex(m, q, 0)], words[shared::cellWordIndex(m, q, 1)],
                                                words[shared::cellWordIndex(m, q, 2)], words[shared::cellWordIndex(m, q, 3)],
                                                shared::cellShift(m, q));
    if (bits == shared::kCellAll) whole[q / 32] |= 1u << (q % 32);
    if (bits != 0u) any[q / 32] |= 1u << (q % 32);
  }
}

CellVisibility CellVisibility::fromBits(const VisibilityBits& bits) {
  CellVisibility out;
  out.points_ = bits.pointCount();
  out.wordsPerPoint_ = 2 * cellMaskWords(bits.level());
  out.masks_.resize(out.points_ * out.wordsPerPoint_);
  for (std::size_t p = 0; p < out.points_; ++p) cellMasks(bits.point(p).data(), bits.level(), out.masks_.data() + p * out.wordsPerPoint_);
  return out;
}

const std::uint32_t* CellVisibility::point(std::size_t p) const {
  HC_CHECK_LT(p, points_);
  return masks_.data() + p * wordsPerPoint_;
}

namespace {

// The widest cell (rows M/2 − 2 … M/2 + 1 at the equator, columns 0 … 3) as
// offsets from its centre: each direction's angle a from the centre, its
// bearing b from the centre's +θ toward +φ, and ΔΩ.
struct CellTemplate {
  std::array<double, shared::kCellDirections> angle{}, bearing{}, weight{};
};
CellTemplate widestCell(int level) {
  const int m = mapSize(level);
  CellTemplate t;
  glm::dvec3 centre(0.0);
  std::array<glm::dvec3, shared::kCellDirections> d{};
  for (std::uint32_t k = 0; k < shared::kCellDirections; ++k) {
    const int row = m / 2 - 2 + static_cast<int>(k / shared::kCellSide), col = static_cast<int>(k % shared::kCellSide);
    d[k] = sphericalToDirection(rowTheta(level, row), colPhi(level, col));
    t.weight[k] = pixelSolidAngle(level, row);
    centre += t.weight[k] * d[k];
  }
  centre = glm::normalize(centre);
  const Spherical s = directionToSpherical(centre);
  const glm::dvec3 eTheta(std::cos(s.theta) * std::sin(s.phi), -std::sin(s.theta), std::cos(s.theta) * std::cos(s.phi));
  const glm::dvec3 ePhi(std::cos(s.phi), 0.0, -std::sin(s.phi));
  for (std::size_t k = 0; k < shared::kCellDirections; ++k) {
    t.angle[k] = std::acos(std::clamp(glm::dot(d[k], centre), -1.0, 1.0));
    t.bearing[k] = std::atan2(glm::dot(d[k], ePhi), glm::dot(d[k], eTheta));
  }
  return t;
}

// ρ_c bilinear at a direction, as the pass looks it up with γ = 0.
std::array<float, 3> rhoAt(const float* texels, int level, const glm::dvec3& w) {
  const Spherical s = directionToSpherical(w);
  const shared::LatLongTaps t = shared::latLongTaps(static_cast<shared::uint>(level), static_cast<float>(s.theta), static_cast<float>(s.phi));
  const std::uint32_t m = static_cast<std::uint32_t>(mapSize(level));
  std::array<float, 3> out{};
  for (std::size_t c = 0; c < 3; ++c) {
    auto at = [&](std::uint32_t row, std::uint32_t col) { return texels[(row * m + col) * shared::kTexelFloats + c]; };
    const float top = at(t.row0, t.col0) + t.tCol * (at(t.row0, t.col1) - at(t.row0, t.col0));
    const float bottom = at(t.row1, t.col0) + t.tCol * (at(t.row1, t.col1) - at(t.row1, t.col0));
    out[c] = top + t.tRow * (bottom - top);
  }
  return out;
}

}  // namespace

std::vector<float> sliceDetail(const float* texels, int level, const float energy[3]) {
  checkCellLevel(level);
  const int across = mapSize(level) / static_cast<int>(shared::kCellSide);
  const float mean = std::max({energy[0], energy[1], energy[2]}) / shared::kTwoPiF;
  std::vector<float> raw(cellCount(level), 0.0f);
  if (!(mean > 0.0f)) return raw;  // a black slice: nothing to get wrong
  const CellTemplate cell = widestCell(level);
  const double texelTheta = kPi / across, texelPhi = kTwoPi / across;
  for (int row = 0; row < across; ++row) {
    for (int col = 0; col < across; ++col) {
      float worst = -1.0f;  // −1: every placement crossed the horizon
      // The texel's centre and its four corners.
      for (int corner = 0; corner < 5; ++corner) {
        const double theta = (row + (corner == 0 ? 0.5 : (corner & 1))) * texelTheta;
        const double phi = (col + (corner == 0 ? 0.5 : ((corner >> 1) & 1))) * texelPhi;
        const glm::dvec3 p = sphericalToDirection(theta, phi);
        const glm::dvec3 eTheta(std::cos(theta) * std::sin(phi), -std::sin(theta), std::cos(theta) * std::cos(phi));
        const glm::dvec3 ePhi(std::cos(phi), 0.0, -std::sin(phi));
        const std::array<float, 3> atCentre = rhoAt(texels, level, p);
        for (double turn : {0.0, 0.5 * kPi}) {
          std::array<double, 3> sum{};
          double weight = 0.0;
          bool acrossHorizon = false;
          for (std::size_t k = 0; k < shared::kCellDirections; ++k) {
            const double b = cell.bearing[k] + turn;
            const glm::dvec3 w = std::cos(cell.angle[k]) * p + std::sin(cell.angle[k]) * (std::cos(b) * eTheta + std::sin(b) * ePhi);
            acrossHorizon = acrossHorizon || w.y < 0.0;
            const std::array<float, 3> rho = rhoAt(texels, level, w);
            for (std::size_t c = 0; c < 3; ++c) sum[c] += cell.weight[k] * rho[c];
            weight += cell.weight[k];
          }
          // A slice is ρ·max(cos θᵢ, 0): across its horizon the mean of a
          // cell is not its centre's value, but there V cuts the cell too
          // (below a surface's tangent plane it sees itself), and the
          // centroid of V·L lies above the kink. Such cells are measured by
          // their neighbours' detail (the 3 × 3 largest below).
          if (acrossHorizon) continue;
          worst = std::max(worst, 0.0f);
          for (std::size_t c = 0; c < 3; ++c) worst = std::max(worst, std::abs(static_cast<float>(sum[c] / weight) - atCentre[c]));
        }
      }
      raw[static_cast<std::size_t>(row * across + col)] = worst < 0.0f ? -1.0f : worst / mean;
    }
  }
  // A texel whose every placement crossed the horizon (the band along it)
  // takes the largest detail measured in its 3 × 3 neighbourhood (rows
  // clamped, columns wrapped): as smooth as the slice beside it.
  std::vector<float> out = raw;
  for (int row = 0; row < across; ++row) {
    for (int col = 0; col < across; ++col) {
      float& d = out[static_cast<std::size_t>(row * across + col)];
      if (d >= 0.0f) continue;
      d = 0.0f;
      for (int dr = -1; dr <= 1; ++dr) {
        const int r = std::clamp(row + dr, 0, across - 1);
        for (int dc = -1; dc <= 1; ++dc) d = std::max(d, raw[static_cast<std::size_t>(r * across + ((col + dc + across) % across))]);
      }
    }
  }
  return out;
}

}  // namespace haarcast
