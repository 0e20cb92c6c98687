// MERL `.binary` BRDFs: reader, validation and nearest-cell lookup (merl.h
// has the layout and the conventions).
#include "haarcast/io/merl.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

#include <glm/geometric.hpp>

#include "haarcast/core/sphere_map.h"
#include "haarcast/io/input_file.h"

namespace haarcast::io {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

// The MERL files were written on little-endian machines and every reader
// since treats them as such.
template <typename T>
T fromLittleEndian(const unsigned char* bytes) {
  std::array<unsigned char, sizeof(T)> raw{};
  std::memcpy(raw.data(), bytes, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw.begin(), raw.end());
  T v;
  std::memcpy(&v, raw.data(), sizeof(T));
  return v;
}

constexpr const char* kChannelName[3] = {"red", "green", "blue"};

// Continuous index → cell, clamped to [0, n−1]; NaN goes to cell 0.
int clampedCell(double continuousIndex, int n) {
  if (!(continuousIndex > 0.0)) return 0;
  return static_cast<int>(std::min(continuousIndex, static_cast<double>(n - 1)));
}

}  // namespace

HalfDiff halfDiffCoordinates(const glm::dvec3& wi, const glm::dvec3& wo) {
  // haarcast (x, y, z) → MERL (z, x, y): normal +Y → +Z, and haarcast's
  // φ = 0 direction (+Z) → MERL's φ = 0 direction (+X).
  const glm::dvec3 in = glm::normalize(glm::dvec3(wi.z, wi.x, wi.y));
  const glm::dvec3 out = glm::normalize(glm::dvec3(wo.z, wo.x, wo.y));
  glm::dvec3 half = in + out;
  const double len = glm::length(half);
  // Opposite directions have no half vector; they are never both above the
  // horizon, so any choice will do.
  half = len > 0.0 ? half / len : glm::dvec3(0.0, 0.0, 1.0);

  HalfDiff hd{};
  hd.thetaHalf = std::acos(std::clamp(half.z, -1.0, 1.0));
  const double phiHalf = std::atan2(half.y, half.x);
  // BRDFRead.cpp: rotate ωᵢ about the normal by −φh, then about the binormal
  // (+Y) by −θh, which takes the half vector to the normal.
  const double cp = std::cos(phiHalf), sp = std::sin(phiHalf);
  const glm::dvec3 t(in.x * cp + in.y * sp, -in.x * sp + in.y * cp, in.z);
  const double ct = std::cos(hd.thetaHalf), st = std::sin(hd.thetaHalf);
  const glm::dvec3 diff(t.x * ct - t.z * st, t.y, t.x * st + t.z * ct);
  hd.thetaDiff = std::acos(std::clamp(diff.z, -1.0, 1.0));
  hd.phiDiff = std::atan2(diff.y, diff.x);
  return hd;
}

int merlThetaHalfIndex(double thetaHalf) {
  // The square root spends half the cells on θh < 22.5°, where the specular
  // peaks are (BRDFRead.cpp's theta_half_index).
  if (!(thetaHalf > 0.0)) return 0;
  return clampedCell(std::sqrt(thetaHalf / (kPi / 2.0)) * kMerlThetaHalfRes, kMerlThetaHalfRes);
}

int merlThetaDiffIndex(double thetaDiff) {
  return clampedCell(thetaDiff / (kPi / 2.0) * kMerlThetaDiffRes, kMerlThetaDiffRes);
}

int merlPhiDiffIndex(double phiDiff) {
  // Reciprocity: swapping ωᵢ and ωₒ turns φd into φd + π, so the table holds
  // [0, π) only.
  if (phiDiff < 0.0) phiDiff += kPi;
  return clampedCell(phiDiff / kPi * kMerlPhiDiffRes, kMerlPhiDiffRes);
}

MerlBrdf::MerlBrdf(std::string name, std::vector<float> rgb, std::size_t repairedCells)
    : name_(std::move(name)), repairedCells_(repairedCells), rgb_(std::move(rgb)) {
  if (rgb_.size() != 3 * kMerlCells) {
    throw std::invalid_argument("MerlBrdf \"" + name_ + "\": " + std::to_string(rgb_.size()) + " values, expected " +
                                std::to_string(3 * kMerlCells));
  }
  for (std::size_t i = 0; i < rgb_.size(); ++i) {
    if (!std::isfinite(rgb_[i])) {
      throw std::invalid_argument("MerlBrdf \"" + name_ + "\": value " + std::to_string(i) + " is not finite");
    }
  }
}

glm::dvec3 MerlBrdf::cell(int thetaHalfIndex, int thetaDiffIndex, int phiDiffIndex) const {
  if (thetaHalfIndex < 0 || thetaHalfIndex >= kMerlThetaHalfRes || thetaDiffIndex < 0 ||
      thetaDiffIndex >= kMerlThetaDiffRes || phiDiffIndex < 0 || phiDiffIndex >= kMerlPhiDiffRes) {
    throw std::out_of_range("MerlBrdf::cell: (" + std::to_string(thetaHalfIndex) + ", " +
                            std::to_string(thetaDiffIndex) + ", " + std::to_string(phiDiffIndex) +
                            ") is outside 90 × 90 × 180");
  }
  const std::size_t k = 3 * merlCellIndex(thetaHalfIndex, thetaDiffIndex, phiDiffIndex);
  return {rgb_[k], rgb_[k + 1], rgb_[k + 2]};
}

glm::dvec3 MerlBrdf::evaluate(const glm::dvec3& wi, const glm::dvec3& wo) const {
  if (wi.y <= 0.0 || wo.y <= 0.0) return glm::dvec3(0.0);
  const HalfDiff hd = halfDiffCoordinates(wi, wo);
  const std::size_t k = 3 * merlCellIndex(merlThetaHalfIndex(hd.thetaHalf), merlThetaDiffIndex(hd.thetaDiff),
                                          merlPhiDiffIndex(hd.phiDiff));
  // Below-horizon cells hold negative markers; they read as no reflection.
  return {std::max(rgb_[k], 0.0f), std::max(rgb_[k + 1], 0.0f), std::max(rgb_[k + 2], 0.0f)};
}

namespace {

// The size is known before a byte is read, and a MERL file has exactly one.
void checkMerlSize(const std::string& path, std::uintmax_t size) {
  if (size != kMerlFileBytes) {
    fail(path, "is " + std::to_string(size) + " bytes; a MERL .binary file is exactly " +
                   std::to_string(kMerlFileBytes) + " (12-byte header + 3 × 1,458,000 doubles)" +
                   (size < kMerlFileBytes ? ", so it is truncated or not a MERL file" : ""));
  }
}

// The header and the three channels from `read(out, n)` (false: the data
// ended), already checked to be kMerlFileBytes long. `path` names errors.
template <typename Read>
std::unique_ptr<MerlBrdf> decodeMerl(const Read& read, const std::string& path, const std::string& name,
                                     const MerlLoadOptions& options) {
  std::array<unsigned char, 12> header{};
  if (!read(header.data(), header.size())) fail(path, "cannot read the MERL header");
  const std::array<std::int32_t, 3> dims{fromLittleEndian<std::int32_t>(header.data()),
                                         fromLittleEndian<std::int32_t>(header.data() + 4),
                                         fromLittleEndian<std::int32_t>(header.data() + 8)};
  if (dims[0] != kMerlThetaHalfRes || dims[1] != kMerlThetaDiffRes || dims[2] != kMerlPhiDiffRes) {
    fail(path, "MERL dims are " + std::to_string(dims[0]) + " × " + std::to_string(dims[1]) + " × " +
                   std::to_string(dims[2]) + ", expected exactly 90 × 90 × 180");
  }

  // Channel-major in the file, interleaved in memory (one cache line per
  // lookup instead of three); read in chunks to keep the peak at the floats.
  std::vector<float> rgb(3 * kMerlCells);
  std::size_t nonFinite = 0;
  std::size_t firstBad = 0;  // (cell, channel) of the first non-finite value
  int firstBadChannel = 0;
  constexpr std::size_t kChunk = 1 << 16;
  std::vector<unsigned char> buffer(kChunk * sizeof(double));
  for (int c = 0; c < 3; ++c) {
    for (std::size_t first = 0; first < kMerlCells; first += kChunk) {
      const std::size_t n = std::min(kChunk, kMerlCells - first);
      if (!read(buffer.data(), n * sizeof(double))) {
        fail(path, std::string("read failed in the ") + kChannelName[c] + " channel (file changed while reading?)");
      }
      for (std::size_t k = 0; k < n; ++k) {
        const double stored = fromLittleEndian<double>(buffer.data() + k * sizeof(double));
        const std::size_t cellIndex = first + k;
        float& value = rgb[3 * cellIndex + static_cast<std::size_t>(c)];
        if (!std::isfinite(stored)) {
          if (nonFinite++ == 0) {
            firstBad = cellIndex;
            firstBadChannel = c;
          }
          value = std::numeric_limits<float>::quiet_NaN();
          continue;
        }
        // Keep "no data" negative (−1 in the files) whatever the scale.
        const double rho = stored < 0.0 ? -1.0 : stored * kMerlScale[c];
        if (rho > static_cast<double>(std::numeric_limits<float>::max())) {
          fail(path, std::string(kChannelName[c]) + " value " + std::to_string(stored) + " of cell " +
                         std::to_string(cellIndex) + " is too large for a reflectance");
        }
        value = static_cast<float>(rho);
      }
    }
  }

  if (nonFinite > 0 && !options.repairNonFinite) {
    const std::size_t phiD = firstBad % kMerlPhiDiffRes;
    const std::size_t thetaD = firstBad / kMerlPhiDiffRes % kMerlThetaDiffRes;
    const std::size_t thetaH = firstBad / kMerlPhiDiffRes / kMerlThetaDiffRes;
    fail(path, std::to_string(nonFinite) + " non-finite value(s); the first is the " + kChannelName[firstBadChannel] +
                   " value of cell (theta_h " + std::to_string(thetaH) + ", theta_d " + std::to_string(thetaD) +
                   ", phi_d " + std::to_string(phiD) + "); MerlLoadOptions::repairNonFinite fills them from their row");
  }
  if (nonFinite > 0) {
    // Mean over φd of the row's finite, measured (non-negative) values.
    for (int c = 0; c < 3; ++c) {
      for (int h = 0; h < kMerlThetaHalfRes; ++h) {
        for (int d = 0; d < kMerlThetaDiffRes; ++d) {
          const auto at = [&](int p) -> float& { return rgb[3 * merlCellIndex(h, d, p) + static_cast<std::size_t>(c)]; };
          double sum = 0.0;
          int count = 0;
          bool hasBad = false;
          for (int p = 0; p < kMerlPhiDiffRes; ++p) {
            const float v = at(p);
            if (std::isnan(v)) {
              hasBad = true;
            } else if (v >= 0.0f) {
              sum += v;
              ++count;
            }
          }
          if (!hasBad) continue;
          if (count == 0) {
            fail(path, std::string("the ") + kChannelName[c] + " row (theta_h " + std::to_string(h) + ", theta_d " +
                           std::to_string(d) + ") has no finite values to repair from");
          }
          for (int p = 0; p < kMerlPhiDiffRes; ++p) {
            if (std::isnan(at(p))) at(p) = static_cast<float>(sum / count);
          }
        }
      }
    }
  }
  return std::make_unique<MerlBrdf>(name, std::move(rgb), nonFinite);
}

}  // namespace

std::unique_ptr<MerlBrdf> loadMerlBrdf(const std::string& path, const MerlLoadOptions& options) {
  if (auto why = whyNotRegularFile(path)) fail(path, "cannot open MERL BRDF: " + *why);
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) fail(path, "cannot open MERL BRDF: " + ec.message());
  checkMerlSize(path, size);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, "cannot open MERL BRDF");
  const auto read = [&](unsigned char* out, std::size_t n) {
    return static_cast<bool>(in.read(reinterpret_cast<char*>(out), static_cast<std::streamsize>(n)));
  };
  return decodeMerl(read, path, std::filesystem::path(path).stem().string(), options);
}

std::unique_ptr<MerlBrdf> parseMerlBrdf(std::string_view bytes, const std::string& name,
                                        const MerlLoadOptions& options) {
  checkMerlSize(name, bytes.size());
  std::size_t pos = 0;
  const auto read = [&](unsigned char* out, std::size_t n) {
    if (bytes.size() - pos < n) return false;
    std::memcpy(out, bytes.data() + pos, n);
    pos += n;
    return true;
  };
  return decodeMerl(read, name, name, options);
}

std::unique_ptr<Brdf> loadMerl(const std::string& path, const MerlLoadOptions& options) {
  return loadMerlBrdf(path, options);
}

}  // namespace haarcast::io
