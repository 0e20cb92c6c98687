// MERL BRDFs: files this test writes cell by cell in the published layout (so
// the reader is checked against the format, not against itself), the frame
// change from haarcast's +Y normal to MERL's +Z, the refusal of malformed
// files, and the physical sanity of the real tables in ../shared/data.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/io/merl.h"

#include "../test_files.h"

namespace haarcast::io {
namespace {

namespace fs = std::filesystem;
using haarcast::testing::TempDir;
using haarcast::testing::writeFile;

constexpr const char* kTempPrefix = "haarcast-merl-test-";

// The published constants, restated here on purpose rather than taken from merl.h.
constexpr int kThetaH = 90, kThetaD = 90, kPhiD = 180;
constexpr double kScale[3] = {1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0};

// Stored value of (channel, iθh, iθd, iφd) → the bytes of a MERL file:
// int32 dims, then red, green, blue channels of doubles, φd fastest. Written
// on a little-endian machine, as the MERL files were.
std::string merlBytes(const std::function<double(int, int, int, int)>& stored,
                      std::array<std::int32_t, 3> dims = {kThetaH, kThetaD, kPhiD}) {
  static_assert(std::endian::native == std::endian::little, "the test writes host-order bytes");
  const std::size_t cells = static_cast<std::size_t>(kThetaH) * kThetaD * kPhiD;
  std::string bytes(12 + 3 * cells * 8, '\0');
  std::memcpy(bytes.data(), dims.data(), 12);
  std::size_t offset = 12;
  for (int c = 0; c < 3; ++c) {
    for (int ih = 0; ih < kThetaH; ++ih) {
      for (int id = 0; id < kThetaD; ++id) {
        for (int ip = 0; ip < kPhiD; ++ip, offset += 8) {
          const double v = stored(c, ih, id, ip);
          std::memcpy(bytes.data() + offset, &v, 8);
        }
      }
    }
  }
  return bytes;
}

template <typename F>
void expectError(const F& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no exception; expected one mentioning \"" << parts.back() << "\"";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    for (const std::string& part : parts) {
      EXPECT_NE(what.find(part), std::string::npos) << "message \"" << what << "\" lacks \"" << part << "\"";
    }
  }
}

glm::dvec3 randomUpper(std::mt19937& rng) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  return sphericalToDirection(std::acos(uni(rng)), kTwoPi * uni(rng));
}

TEST(MerlBrdf, LambertFileReadsBackAsAlbedoOverPi) {
  TempDir dir(kTempPrefix);
  const glm::dvec3 albedo(0.8, 0.5, 0.25);
  const std::string path = writeFile(dir / "lambert-test.binary", merlBytes([&](int c, int, int, int) {
                                       return albedo[c] / kPi / kScale[c];
                                     }));
  const auto start = std::chrono::steady_clock::now();
  const std::unique_ptr<Brdf> brdf = loadMerl(path);
  std::cout << "[ timing   ] loadMerl (synthetic): "
            << std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() << " ms\n";
  EXPECT_EQ(brdf->name(), "lambert-test");
  std::mt19937 rng(7);
  for (int k = 0; k < 2000; ++k) {
    const glm::dvec3 wi = randomUpper(rng), wo = randomUpper(rng);
    const glm::dvec3 rho = brdf->evaluate(wi, wo);
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(rho[c], albedo[c] / kPi, 1e-6 * albedo[c]) << "channel " << c;
  }
  // Below the horizon, either way round, nothing.
  EXPECT_EQ(brdf->evaluate({0.0, -0.5, 0.866}, {0.0, 1.0, 0.0}), glm::dvec3(0.0));
  EXPECT_EQ(brdf->evaluate({0.0, 1.0, 0.0}, {0.6, -0.8, 0.0}), glm::dvec3(0.0));
}

// Rusinkiewicz's angles from haarcast vectors with no frame change at all:
// θh from the normal (+Y), θd = ∠(ωᵢ, h), φd the angle of ωᵢ about h from the
// plane of n and h, measured from t = b × h toward b = n × h / |n × h| (the
// images of MERL's x and y axes after it rotates h onto its normal).
HalfDiff frameFreeAngles(const glm::dvec3& wi, const glm::dvec3& wo) {
  const glm::dvec3 n(0.0, 1.0, 0.0);
  const glm::dvec3 h = glm::normalize(wi + wo);
  const glm::dvec3 b = glm::normalize(glm::cross(n, h));
  const glm::dvec3 t = glm::cross(b, h);
  return {std::acos(std::clamp(h.y, -1.0, 1.0)), std::acos(std::clamp(glm::dot(wi, h), -1.0, 1.0)),
          std::atan2(glm::dot(wi, b), glm::dot(wi, t))};
}

TEST(MerlBrdf, CellsAreFoundWhereTheFormatPutsThem) {
  // Each channel stores one coordinate's index, so every lookup says which
  // cell it read.
  TempDir dir(kTempPrefix);
  const std::string path = writeFile(dir / "indices.binary", merlBytes([](int c, int ih, int id, int ip) {
                                       return static_cast<double>(c == 0 ? ih : c == 1 ? id : ip);
                                     }));
  const std::unique_ptr<Brdf> brdf = loadMerl(path);
  std::mt19937 rng(11);
  int checked = 0;
  for (int k = 0; k < 20000; ++k) {
    const glm::dvec3 wi = randomUpper(rng), wo = randomUpper(rng);
    const HalfDiff a = frameFreeAngles(wi, wo);
    double phi = a.phiDiff < 0.0 ? a.phiDiff + kPi : a.phiDiff;
    const double continuous[3] = {std::sqrt(a.thetaHalf / (kPi / 2.0)) * kThetaH, a.thetaDiff / (kPi / 2.0) * kThetaD,
                                  phi / kPi * kPhiD};
    // Skip pairs within rounding of a cell boundary.
    bool nearEdge = false;
    for (const double x : continuous) nearEdge |= std::abs(x - std::round(x)) < 1e-6;
    if (nearEdge) continue;
    const glm::dvec3 rho = brdf->evaluate(wi, wo);
    const int maxIndex[3] = {kThetaH - 1, kThetaD - 1, kPhiD - 1};
    for (int c = 0; c < 3; ++c) {
      const int expected = std::min(static_cast<int>(continuous[c]), maxIndex[c]);
      ASSERT_EQ(static_cast<int>(std::lround(rho[c] / kScale[c])), expected)
          << "coordinate " << c << " for ωi " << wi.x << "," << wi.y << "," << wi.z << " ωo " << wo.x << "," << wo.y
          << "," << wo.z;
    }
    ++checked;
  }
  EXPECT_GT(checked, 19000);

  // θh's cells are non-linear: a mirror pair at θh has cell ⌊√(θh/90°)·90⌋.
  for (const double deg : {0.5, 3.0, 10.0, 22.5, 45.0, 80.0}) {
    const double th = deg * kPi / 180.0;
    const glm::dvec3 w = sphericalToDirection(th, 0.3);  // ωᵢ = ωₒ: h = ω, θd = 0
    const int expected = static_cast<int>(std::sqrt(deg / 90.0) * 90.0);
    EXPECT_EQ(static_cast<int>(std::lround(brdf->evaluate(w, w)[0] / kScale[0])), expected) << deg << "°";
  }
  // The three index helpers agree with the format.
  EXPECT_EQ(merlThetaHalfIndex(kPi / 8.0), 45);
  EXPECT_EQ(merlThetaDiffIndex(kPi / 4.0), 45);
  EXPECT_EQ(merlPhiDiffIndex(-kPi / 2.0), 90);
  EXPECT_EQ(merlPhiDiffIndex(kPi), 179);
  EXPECT_EQ(merlThetaHalfIndex(-1.0), 0);
  EXPECT_EQ(merlThetaHalfIndex(std::numeric_limits<double>::quiet_NaN()), 0);
}

TEST(MerlBrdf, NegativeCellsAreBelowTheHorizonAndReadZero) {
  TempDir dir(kTempPrefix);
  // Red has no data beyond θd index 45; green never; blue everywhere 1.
  const std::string path = writeFile(dir / "horizon.binary", merlBytes([](int c, int, int id, int) {
                                       if (c == 0) return id > 45 ? -1.0 : 1500.0;
                                       return c == 1 ? -1.0 : 1500.0 / 1.66;
                                     }));
  const std::unique_ptr<MerlBrdf> brdf = loadMerlBrdf(path);
  EXPECT_LT(brdf->cell(0, 80, 0).x, 0.0);
  const glm::dvec3 n(0.0, 1.0, 0.0);
  const glm::dvec3 grazing = sphericalToDirection(85.0 * kPi / 180.0, 0.0);
  const glm::dvec3 back = sphericalToDirection(85.0 * kPi / 180.0, kPi);
  EXPECT_LT(glm::distance(brdf->evaluate(n, n), glm::dvec3(1.0, 0.0, 1.0)), 1e-6);            // θd = 0
  EXPECT_LT(glm::distance(brdf->evaluate(grazing, back), glm::dvec3(0.0, 0.0, 1.0)), 1e-6);  // θd = 85°
}

TEST(MerlBrdf, RefusesMalformedFiles) {
  TempDir dir(kTempPrefix);
  const std::string good = merlBytes([](int, int, int, int) { return 1.0; });
  std::string nan = good;
  const double q = std::numeric_limits<double>::quiet_NaN();
  std::memcpy(nan.data() + 12 + 8 * (1458000 + 5), &q, 8);  // green, cell 5
  const std::string wrongDims = merlBytes([](int, int, int, int) { return 1.0; }, {90, 180, 90});
  const std::string byteSwapped = merlBytes([](int, int, int, int) { return 1.0; }, {0x5a000000, 0x5a000000, -0x4c000000});

  const std::string truncated = writeFile(dir / "truncated.binary", good.substr(0, good.size() - 8));
  expectError([&] { loadMerl(truncated); }, {truncated, "34992004 bytes", "truncated"});
  const std::string tooLong = writeFile(dir / "long.binary", good + "x");
  expectError([&] { loadMerl(tooLong); }, {tooLong, "34992013 bytes"});
  const std::string dims = writeFile(dir / "dims.binary", wrongDims);
  expectError([&] { loadMerl(dims); }, {dims, "dims are 90 × 180 × 90"});
  const std::string swapped = writeFile(dir / "swapped.binary", byteSwapped);
  expectError([&] { loadMerl(swapped); }, {swapped, "dims"});
  const std::string bad = writeFile(dir / "nan.binary", nan);
  expectError([&] { loadMerl(bad); }, {bad, "1 non-finite", "green", "theta_h 0, theta_d 0, phi_d 5"});
  const std::string empty = writeFile(dir / "empty.binary", "");
  expectError([&] { loadMerl(empty); }, {empty, "0 bytes"});
  const std::string missing = (dir / "missing.binary").string();
  expectError([&] { loadMerl(missing); }, {missing, "cannot open"});
  EXPECT_THROW(MerlBrdf("short", std::vector<float>(10)), std::invalid_argument);
}

TEST(MerlBrdf, RepairFillsNonFiniteCellsFromTheirRow) {
  TempDir dir(kTempPrefix);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // Row (θh 0, θd 3) of red: φd index p holds p, except three NaNs and one
  // below-horizon marker that must not count in the mean.
  const std::string path = writeFile(dir / "holes.binary", merlBytes([&](int c, int ih, int id, int ip) {
                                       if (c == 0 && ih == 0 && id == 3) {
                                         if (ip == 10 || ip == 11 || ip == 100) return nan;
                                         if (ip == 20) return -1.0;
                                         return 1500.0 * ip;
                                       }
                                       return 1500.0;
                                     }));
  expectError([&] { loadMerl(path); }, {path, "3 non-finite", "red", "repairNonFinite"});
  MerlLoadOptions repair;
  repair.repairNonFinite = true;
  const std::unique_ptr<MerlBrdf> brdf = loadMerlBrdf(path, repair);
  EXPECT_EQ(brdf->repairedCells(), 3u);
  const double mean = (179.0 * 180.0 / 2.0 - 10 - 11 - 100 - 20) / (180 - 4);
  EXPECT_NEAR(brdf->cell(0, 3, 11).x, mean, 1e-4);
  EXPECT_NEAR(brdf->cell(0, 3, 100).x, mean, 1e-4);
  EXPECT_EQ(brdf->cell(0, 3, 12).x, 12.0);
  EXPECT_EQ(brdf->cell(0, 3, 20).x, -1.0);
  EXPECT_NEAR(brdf->cell(0, 3, 11).y, 1.15, 1e-6);

  // A row with nothing finite cannot be repaired.
  const std::string hopeless = writeFile(dir / "hopeless.binary", merlBytes([&](int c, int ih, int id, int) {
                                           return c == 2 && ih == 5 && id == 7 ? nan : 1.0;
                                         }));
  expectError([&] { loadMerl(hopeless, repair); }, {hopeless, "blue row (theta_h 5, theta_d 7)"});
}

// ------------------------------------------------------------ real tables

#ifdef HAARCAST_SHARED_DATA
const fs::path kBrdfs = fs::path(HAARCAST_SHARED_DATA) / "brdfs";
#else
const fs::path kBrdfs;
#endif

std::vector<fs::path> sharedMerlFiles() {
  std::vector<fs::path> files;
  std::error_code ec;
  if (kBrdfs.empty() || !fs::is_directory(kBrdfs, ec)) return files;
  for (const auto& entry : fs::directory_iterator(kBrdfs, ec)) {
    if (entry.path().extension() == ".binary") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// ∫ ρ cos θᵢ dωᵢ in (θ, φ) with dω = sin θ dθ dφ: fine in θ near the normal
// where a metal's lobe is at normal incidence.
glm::dvec3 albedo(const Brdf& brdf, const glm::dvec3& wo, int nTheta, int nPhi) {
  glm::dvec3 sum(0.0);
  const double dTheta = (kPi / 2.0) / nTheta, dPhi = kTwoPi / nPhi;
  for (int i = 0; i < nTheta; ++i) {
    const double theta = (i + 0.5) * dTheta;
    glm::dvec3 ring(0.0);
    for (int j = 0; j < nPhi; ++j) ring += brdf.evaluate(sphericalToDirection(theta, (j + 0.5) * dPhi), wo);
    sum += ring * (std::cos(theta) * std::sin(theta));
  }
  return sum * dTheta * dPhi;
}

TEST(MerlBrdfSharedData, RealTablesArePhysical) {
  const std::vector<fs::path> files = sharedMerlFiles();
  if (files.empty()) GTEST_SKIP() << "no ../shared/data/brdfs/*.binary (see shared/data/SOURCES.md)";
  for (const fs::path& file : files) {
    SCOPED_TRACE(file.filename().string());
    const auto start = std::chrono::steady_clock::now();
    // Repair on: a synthesised table may carry NaNs where its fit was
    // evaluated at a degenerate angle (merl.h, MerlLoadOptions).
    MerlLoadOptions repair;
    repair.repairNonFinite = true;
    const std::unique_ptr<MerlBrdf> brdf = loadMerlBrdf(file.string(), repair);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    std::cout << "[ timing   ] loadMerl(" << file.filename().string() << "): " << ms << " ms, "
              << brdf->repairedCells() << " non-finite values repaired\n";
    EXPECT_LT(brdf->repairedCells(), kMerlCells / 1000);
    EXPECT_EQ(brdf->name(), file.stem().string());

    // Reciprocity: swapping the directions turns φd into φd + π, which the
    // fold maps to the same cell; only pairs on a cell boundary may differ.
    std::mt19937 rng(3);
    int asymmetric = 0;
    const int pairs = 20000;
    for (int k = 0; k < pairs; ++k) {
      const glm::dvec3 a = randomUpper(rng), b = randomUpper(rng);
      const glm::dvec3 ab = brdf->evaluate(a, b), ba = brdf->evaluate(b, a);
      for (int c = 0; c < 3; ++c) {
        ASSERT_GE(ab[c], 0.0);
        ASSERT_TRUE(std::isfinite(ab[c]));
      }
      if (glm::length(ab - ba) > 1e-6 * (glm::length(ab) + 1e-12)) ++asymmetric;
    }
    EXPECT_LT(asymmetric, pairs / 1000) << asymmetric << " of " << pairs << " pairs are not reciprocal";

    // Energy: the directional albedo at normal incidence is below 1 and
    // above 0 in every channel.
    const glm::dvec3 a = albedo(*brdf, glm::dvec3(0.0, 1.0, 0.0), 1800, 90);
    std::cout << "[ albedo   ] " << file.filename().string() << " at normal incidence: " << a.x << " " << a.y << " "
              << a.z << "\n";
    for (int c = 0; c < 3; ++c) {
      EXPECT_GT(a[c], 0.0);
      EXPECT_LT(a[c], 1.0);
    }

    // A slice table builds from it, finite and non-negative in the mean.
    SliceTableOptions options;
    options.level = 4;
    options.thetaSamples = 4;
    options.supersampling = 2;
    const BrdfSliceTable table = BrdfSliceTable::build(*brdf, options);
    for (int c = 0; c < 3; ++c) {
      for (int t = 0; t < 4; ++t) {
        EXPECT_GT(table.slice(c, t).scaling(), 0.0f);
        for (const float v : table.slice(c, t).coefficients()) ASSERT_TRUE(std::isfinite(v));
      }
    }
  }
}

}  // namespace
}  // namespace haarcast::io
