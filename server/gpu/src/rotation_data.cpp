#include "haarcast/gpu/rotation_data.h"

#include <bit>
#include <cstddef>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "haarcast/core/rotate_haar.h"

namespace haarcast::gpu {
namespace {

constexpr std::uint32_t kHeaderWords = 4;

void checkLevel(const BrdfSliceTable& table, const char* who) {
  const int level = table.level();
  if (level < kMinRotationLevel || level > kMaxRotationLevel) {
    throw std::invalid_argument(std::string(who) + ": the rotation shaders take map levels " +
                                std::to_string(kMinRotationLevel) + " to " + std::to_string(kMaxRotationLevel) +
                                ", the slice table has level " + std::to_string(level));
  }
}

// Grows methodData by `words` and returns where the new block starts,
// refusing sizes the shaders' 32-bit offsets cannot address.
std::uint32_t reserveBlock(std::vector<std::uint32_t>& methodData, std::size_t words, const char* who) {
  const std::size_t base = methodData.size();
  if (words > std::numeric_limits<std::uint32_t>::max() - base) {
    throw std::invalid_argument(std::string(who) + ": the method data would hold " + std::to_string(base + words) +
                                " words, past the 2^32 that 32-bit offsets address");
  }
  methodData.resize(base + words, 0u);
  return static_cast<std::uint32_t>(base);
}

std::uint32_t bitsOf(double v) { return std::bit_cast<std::uint32_t>(static_cast<float>(v)); }
std::uint32_t bitsOf(float v) { return std::bit_cast<std::uint32_t>(v); }

std::uint32_t appendHaar(const BrdfSliceTable& table, std::uint32_t sliceBase, std::vector<std::uint32_t>& out) {
  const std::size_t m = static_cast<std::size_t>(mapSize(table.level()));
  const std::size_t perMap = (2 * m - 1) * m;
  const int slices = table.thetaSamples();
  const std::uint32_t base =
      reserveBlock(out, kHeaderWords + static_cast<std::size_t>(slices) * 3 * perMap, "haar rotation data");
  out[base] = sliceBase;
  for (int t = 0; t < slices; ++t) {
    for (int c = 0; c < BrdfSliceTable::kChannels; ++c) {
      const PixelDifferences d = refinedPixelDifferences(table.slice(c, t));
      std::size_t at = base + kHeaderWords + (static_cast<std::size_t>(t) * 3 + static_cast<std::size_t>(c)) * perMap;
      for (double v : d.theta) out[at++] = bitsOf(v);
      for (double v : d.phi) out[at++] = bitsOf(v);
    }
  }
  return base;
}

// Faithful: per object the vertical moments, per map its integral and its
// finest details as derivative samples at block centres (rotateHaar's
// faithfulDifferences: ∂f/∂θ ≈ −v/Δθ, ∂f/∂φ ≈ −h/Δφ).
std::uint32_t appendHaarFaithful(const BrdfSliceTable& table, std::uint32_t sliceBase,
                                 std::vector<std::uint32_t>& out) {
  const int n = table.level();
  const std::size_t m = static_cast<std::size_t>(mapSize(n)), half = m / 2;
  const std::size_t perMap = 1 + 2 * half * half;
  const int slices = table.thetaSamples();
  const std::uint32_t base = reserveBlock(out, kHeaderWords + (m - 1) + static_cast<std::size_t>(slices) * 3 * perMap,
                                          "haar (faithful) rotation data");
  out[base] = sliceBase;
  out[base + 1] = 1u;  // variant: faithful
  for (int l = 0; l < n; ++l)
    for (int i = 0; i < (1 << l); ++i)
      out[base + kHeaderWords + static_cast<std::size_t>((1 << l) - 1 + i)] = bitsOf(verticalDetailMoment(n, l, i));
  const double dTheta = kPi / static_cast<double>(m), dPhi = kTwoPi / static_cast<double>(m);
  for (int t = 0; t < slices; ++t) {
    for (int c = 0; c < BrdfSliceTable::kChannels; ++c) {
      const HaarMap& f = table.slice(c, t);
      std::size_t at =
          base + kHeaderWords + (m - 1) + (static_cast<std::size_t>(t) * 3 + static_cast<std::size_t>(c)) * perMap;
      out[at++] = bitsOf(integralFromCoefficients(f));
      for (int i = 0; i < static_cast<int>(half); ++i)
        for (int j = 0; j < static_cast<int>(half); ++j)
          out[at++] = bitsOf(-f.detail(Band::Vertical, n - 1, i, j) / dTheta);
      for (int i = 0; i < static_cast<int>(half); ++i)
        for (int j = 0; j < static_cast<int>(half); ++j)
          out[at++] = bitsOf(-f.detail(Band::Horizontal, n - 1, i, j) / dPhi);
    }
  }
  return base;
}

std::uint32_t appendTable(const std::array<const SliceRotator*, 3>& rotators, const BrdfSliceTable& table,
                          std::uint32_t sliceBase, std::vector<std::uint32_t>& out) {
  const TableCopies first = tableCopies(*rotators[0]);
  const std::size_t n =
      static_cast<std::size_t>(mapSize(table.level())) * static_cast<std::size_t>(mapSize(table.level()));
  const std::size_t perSlice = static_cast<std::size_t>(first.elevations) * static_cast<std::size_t>(first.spins);
  const auto slices = static_cast<std::size_t>(table.thetaSamples());
  const std::uint32_t base = reserveBlock(out, kHeaderWords + slices * 3 * perSlice * n, "table rotation data");
  out[base] = sliceBase;
  out[base + 1] = static_cast<std::uint32_t>(first.elevations);
  out[base + 2] = static_cast<std::uint32_t>(first.spins);
  for (int c = 0; c < 3; ++c) {
    const TableCopies copies = tableCopies(*rotators[static_cast<std::size_t>(c)]);
    if (copies.elevations != first.elevations || copies.spins != first.spins) {
      throw std::invalid_argument("table rotation data: the channels' table rotators use different grids");
    }
    for (std::size_t t = 0; t < slices; ++t) {
      for (std::size_t q = 0; q < perSlice; ++q) {
        const HaarMap& copy = copies.copies[t * perSlice + q];
        std::size_t at = base + kHeaderWords + ((t * 3 + static_cast<std::size_t>(c)) * perSlice + q) * n;
        for (float v : copy.coefficients()) out[at++] = bitsOf(v);
      }
    }
  }
  return base;
}

std::uint32_t appendMatrix(const SliceRotator& rotator, const BrdfSliceTable& table, std::vector<std::uint32_t>& out) {
  const std::vector<SparseMatrixView> matrices = elevationMatrixViews(rotator);
  const std::size_t n =
      static_cast<std::size_t>(mapSize(table.level())) * static_cast<std::size_t>(mapSize(table.level()));
  std::size_t words = kHeaderWords + matrices.size();
  for (const SparseMatrixView& a : matrices) words += (n + 1) + 2 * a.value.size();
  const std::uint32_t base = reserveBlock(out, words, "matrix rotation data");
  out[base] = static_cast<std::uint32_t>(matrices.size());
  std::size_t at = kHeaderWords + matrices.size();  // relative to base
  for (std::size_t k = 0; k < matrices.size(); ++k) {
    const SparseMatrixView& a = matrices[k];
    if (a.rowStart.size() != n + 1) {
      throw std::invalid_argument("matrix rotation data: matrix " + std::to_string(k) + " has " +
                                  std::to_string(a.rowStart.size()) +
                                  " row offsets, expected N + 1 = " + std::to_string(n + 1));
    }
    out[base + kHeaderWords + k] = static_cast<std::uint32_t>(at);
    for (std::uint32_t r : a.rowStart) out[base + at++] = r;
    for (std::size_t e = 0; e < a.value.size(); ++e) {
      out[base + at++] = a.column[e];
      out[base + at++] = bitsOf(a.value[e]);
    }
  }
  return base;
}

}  // namespace

std::uint32_t appendRotationData(RotationMethod method, const BrdfSliceTable& table, std::uint32_t sliceBase,
                                 std::vector<std::uint32_t>& methodData, const RotatorOptions& options) {
  checkLevel(table, "appendRotationData");
  switch (method) {
    case RotationMethod::Haar:
      if (options.haarVariant == HaarVariant::Local) {
        throw std::invalid_argument(
            "appendRotationData: the haar shader implements the refined and faithful "
            "variants, not local");
      }
      if (options.haarStartLevel >= 0 && options.haarStartLevel != table.level() - 1) {
        throw std::invalid_argument("appendRotationData: the haar shader starts from the finest detail level " +
                                    std::to_string(table.level() - 1) + ", not " +
                                    std::to_string(options.haarStartLevel));
      }
      return options.haarVariant == HaarVariant::Faithful ? appendHaarFaithful(table, sliceBase, methodData)
                                                          : appendHaar(table, sliceBase, methodData);
    case RotationMethod::Spatial: return reserveBlock(methodData, 0, "spatial rotation data");
    case RotationMethod::Table:
    case RotationMethod::Matrix: {
      std::array<std::unique_ptr<SliceRotator>, 3> owned;
      std::array<const SliceRotator*, 3> rotators{};
      for (int c = 0; c < 3; ++c) {
        // The matrices do not depend on the slices: one rotator serves all channels.
        if (method == RotationMethod::Matrix && c > 0) {
          rotators[static_cast<std::size_t>(c)] = rotators[0];
          continue;
        }
        owned[static_cast<std::size_t>(c)] = makeRotator(method, table.channelSlices(c), options);
        rotators[static_cast<std::size_t>(c)] = owned[static_cast<std::size_t>(c)].get();
      }
      return appendRotationData(rotators, table, sliceBase, methodData);
    }
    case RotationMethod::Fused:
      // fused keeps no rotation data: it samples the slices' pixel form.
      throw std::invalid_argument("appendRotationData: fused rotates nothing ahead (it samples the slices' pixel form)");
    case RotationMethod::Splitsum:
      throw std::invalid_argument("appendRotationData: splitsum keeps no slices (it reads the prefiltered light)");
  }
  throw std::invalid_argument("appendRotationData: unknown rotation method");
}

std::uint32_t appendRotationData(const std::array<const SliceRotator*, 3>& channelRotators, const BrdfSliceTable& table,
                                 std::uint32_t sliceBase, std::vector<std::uint32_t>& methodData) {
  checkLevel(table, "appendRotationData");
  for (const SliceRotator* r : channelRotators) {
    if (r == nullptr) throw std::invalid_argument("appendRotationData: a channel's rotator is missing");
    if (r->method() != channelRotators[0]->method()) {
      throw std::invalid_argument("appendRotationData: the channels' rotators mix methods " +
                                  std::string(methodName(r->method())) + " and " +
                                  std::string(methodName(channelRotators[0]->method())));
    }
    if (r->level() != table.level() || r->sliceCount() != static_cast<std::size_t>(table.thetaSamples())) {
      throw std::invalid_argument("appendRotationData: a rotator holds " + std::to_string(r->sliceCount()) +
                                  " slices of level " + std::to_string(r->level()) + ", the table " +
                                  std::to_string(table.thetaSamples()) + " of level " + std::to_string(table.level()));
    }
  }
  switch (channelRotators[0]->method()) {
    case RotationMethod::Table: return appendTable(channelRotators, table, sliceBase, methodData);
    case RotationMethod::Matrix: return appendMatrix(*channelRotators[0], table, methodData);
    default:
      throw std::invalid_argument("appendRotationData: prebuilt rotators are for table or matrix, not " +
                                  std::string(methodName(channelRotators[0]->method())));
  }
}

}  // namespace haarcast::gpu
