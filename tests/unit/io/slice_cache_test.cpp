// The slice-table cache: a miss builds and writes, a hit builds nothing and
// returns the same table bit for bit, and every kind of stale or damaged file
// (one flipped byte, other options, another key, another version, a cut-off
// file) is rebuilt and rewritten. A cache that cannot be written never stops
// the table from being built.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/io/slice_cache.h"

#include "../test_files.h"

namespace haarcast::io {
namespace {

namespace fs = std::filesystem;
using haarcast::testing::readFile;
using haarcast::testing::TempDir;

constexpr const char* kTempPrefix = "haarcast-cache-test-";

SliceTableOptions smallOptions() {
  SliceTableOptions o;
  o.level = 4;
  o.thetaSamples = 4;
  o.supersampling = 2;
  return o;
}

std::unique_ptr<Brdf> testBrdf() { return makePhong({0.1, 0.2, 0.3}, {0.5, 0.4, 0.3}, 30.0); }

void expectSameTable(const BrdfSliceTable& a, const BrdfSliceTable& b) {
  ASSERT_EQ(a.level(), b.level());
  ASSERT_EQ(a.thetaSamples(), b.thetaSamples());
  for (int t = 0; t < a.thetaSamples(); ++t) {
    ASSERT_EQ(a.thetaOut(t), b.thetaOut(t));
    for (int c = 0; c < BrdfSliceTable::kChannels; ++c) {
      const auto x = a.slice(c, t).coefficients(), y = b.slice(c, t).coefficients();
      ASSERT_EQ(x.size(), y.size());
      ASSERT_EQ(std::memcmp(x.data(), y.data(), x.size_bytes()), 0) << "slice (" << c << ", " << t << ")";
    }
  }
}

// Calls loadOrBuildSliceTable and counts progress calls: 0 means a hit.
struct Call {
  BrdfSliceTable table;
  SliceCacheStatus status;
  int progressCalls = 0;
};
Call cached(const Brdf& brdf, const SliceTableOptions& options, const fs::path& dir, const std::string& key) {
  Call call;
  call.table = loadOrBuildSliceTable(
      brdf, options, dir.string(), key, [&](int, int) { ++call.progressCalls; }, &call.status);
  return call;
}

void flipByte(const std::string& path, std::size_t offset) {
  std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
  f.seekg(static_cast<std::streamoff>(offset));
  char c = 0;
  f.read(&c, 1);
  c = static_cast<char>(c ^ 0x5a);
  f.seekp(static_cast<std::streamoff>(offset));
  f.write(&c, 1);
}

std::size_t filesIn(const fs::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(SliceCache, MissBuildsAndWritesThenHitBuildsNothing) {
  TempDir tmp(kTempPrefix);
  const fs::path dir = tmp / "nested" / "cache";  // created on demand
  const auto brdf = testBrdf();
  const Call first = cached(*brdf, smallOptions(), dir, "phong-30");
  EXPECT_FALSE(first.status.hit);
  EXPECT_TRUE(first.status.written);
  EXPECT_EQ(first.status.reason, "no cache file");
  EXPECT_TRUE(first.status.error.empty()) << first.status.error;
  EXPECT_EQ(first.progressCalls, 4);
  ASSERT_TRUE(fs::is_regular_file(first.status.path));
  EXPECT_EQ(filesIn(dir), 1u) << "a temporary file was left behind";

  const Call second = cached(*brdf, smallOptions(), dir, "phong-30");
  EXPECT_TRUE(second.status.hit) << second.status.reason;
  EXPECT_EQ(second.progressCalls, 0);
  EXPECT_EQ(second.status.path, first.status.path);
  expectSameTable(first.table, second.table);
  expectSameTable(second.table, BrdfSliceTable::build(*brdf, smallOptions()));
}

TEST(SliceCache, DamagedOrStaleFilesAreRebuiltAndRewritten) {
  const auto brdf = testBrdf();
  const SliceTableOptions options = smallOptions();
  const std::string key = "phong-30";
  // Offsets found in the file, so the cases follow cache_file.h's layout.
  const auto offsetOf = [](const std::string& path, const std::string& text) {
    const std::size_t at = readFile(path).find(text);
    EXPECT_NE(at, std::string::npos) << text;
    return at;
  };
  struct Case {
    std::string label;
    std::function<void(const std::string&)> damage;
    std::string reason;
  };
  const std::vector<Case> cases = {
      {"one payload byte", [&](const std::string& p) { flipByte(p, offsetOf(p, "channels=3") + 100); }, "checksum"},
      {"one checksum byte", [&](const std::string& p) { flipByte(p, fs::file_size(p) - 3); }, "checksum"},
      {"the magic", [](const std::string& p) { flipByte(p, 1); }, "magic"},
      {"the version", [](const std::string& p) { flipByte(p, 8); }, "version"},
      {"the level", [&](const std::string& p) { flipByte(p, offsetOf(p, "level=") + 6); }, "options differ"},
      {"the key", [&](const std::string& p) { flipByte(p, offsetOf(p, key) + 1); }, "another key"},
      {"cut short", [](const std::string& p) { fs::resize_file(p, fs::file_size(p) - 1); }, "wrong size"},
      {"grown", [](const std::string& p) { fs::resize_file(p, fs::file_size(p) + 1); }, "wrong size"},
      {"emptied", [](const std::string& p) { fs::resize_file(p, 0); }, "wrong size"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.label);
    TempDir dir(kTempPrefix);
    const Call built = cached(*brdf, options, dir.path(), key);
    ASSERT_TRUE(built.status.written);
    c.damage(built.status.path);

    const Call rebuilt = cached(*brdf, options, dir.path(), key);
    EXPECT_FALSE(rebuilt.status.hit);
    EXPECT_EQ(rebuilt.progressCalls, options.thetaSamples);
    EXPECT_NE(rebuilt.status.reason.find(c.reason), std::string::npos) << rebuilt.status.reason;
    EXPECT_TRUE(rebuilt.status.written);
    expectSameTable(rebuilt.table, built.table);

    const Call hit = cached(*brdf, options, dir.path(), key);
    EXPECT_TRUE(hit.status.hit) << "the rebuilt file was not rewritten: " << hit.status.reason;
  }
}

TEST(SliceCache, OtherOptionsOrKeysAreOtherEntries) {
  TempDir dir(kTempPrefix);
  const auto brdf = testBrdf();
  SliceTableOptions options = smallOptions();
  ASSERT_TRUE(cached(*brdf, options, dir.path(), "k").status.written);

  SliceTableOptions finer = options;
  finer.supersampling = 3;
  const Call other = cached(*brdf, finer, dir.path(), "k");
  EXPECT_FALSE(other.status.hit);
  EXPECT_EQ(other.progressCalls, options.thetaSamples);
  SliceTableOptions moreSlices = options;
  moreSlices.thetaSamples = 5;
  EXPECT_EQ(cached(*brdf, moreSlices, dir.path(), "k").progressCalls, 5);
  EXPECT_FALSE(cached(*brdf, options, dir.path(), "another material").status.hit);
  // Every entry is kept: the first one still hits.
  EXPECT_TRUE(cached(*brdf, options, dir.path(), "k").status.hit);
  EXPECT_EQ(filesIn(dir.path()), 4u);
}

TEST(SliceCache, AFileUnderAnotherKeysNameIsAMiss) {
  // What a hash collision would look like: the right name, the wrong contents.
  TempDir dir(kTempPrefix);
  const auto brdf = testBrdf();
  const Call a = cached(*brdf, smallOptions(), dir.path(), "key A");
  fs::rename(a.status.path, dir / sliceCacheFileName("key B", smallOptions()));
  const Call b = cached(*brdf, smallOptions(), dir.path(), "key B");
  EXPECT_FALSE(b.status.hit);
  EXPECT_NE(b.status.reason.find("another key"), std::string::npos) << b.status.reason;
}

TEST(SliceCache, AnUnusableDirectoryStillGivesTheTable) {
  TempDir tmp(kTempPrefix);
  // A regular file where the directory should be: fails even for root, which
  // permission bits would not stop.
  const fs::path blocker = tmp / "not-a-directory";
  std::ofstream(blocker) << "x";
  const auto brdf = testBrdf();
  const Call call = cached(*brdf, smallOptions(), blocker / "cache", "k");
  EXPECT_FALSE(call.status.hit);
  EXPECT_FALSE(call.status.written);
  EXPECT_FALSE(call.status.error.empty());
  EXPECT_EQ(call.progressCalls, 4);
  expectSameTable(call.table, BrdfSliceTable::build(*brdf, smallOptions()));
  // Without a status the failure goes to stderr, and still nothing throws.
  EXPECT_NO_THROW(loadOrBuildSliceTable(*brdf, smallOptions(), (blocker / "cache").string(), "k"));
  EXPECT_NO_THROW(loadOrBuildSliceTable(*brdf, smallOptions(), blocker.string(), "k"));
}

TEST(SliceCache, BadOptionsAreTheBuildersError) {
  TempDir dir(kTempPrefix);
  SliceTableOptions options = smallOptions();
  options.level = -1;
  EXPECT_THROW(loadOrBuildSliceTable(*testBrdf(), options, dir.path().string(), "k"), std::invalid_argument);
  options = smallOptions();
  options.thetaSamples = 0;
  EXPECT_THROW(loadOrBuildSliceTable(*testBrdf(), options, dir.path().string(), "k"), std::invalid_argument);
}

TEST(SliceCache, EncodeDecodeRoundTripAndRefusals) {
  const auto brdf = testBrdf();
  const SliceTableOptions options = smallOptions();
  const BrdfSliceTable table = BrdfSliceTable::build(*brdf, options);
  const std::string bytes = encodeSliceTable(table, options, "key");
  // A cache file (cache_file.h) whose payload is 4 θₒ and 3·4 level-4 slices.
  const std::size_t optionsBytes = std::string("level=4 thetaSamples=4 supersampling=2 channels=3").size();
  EXPECT_EQ(bytes.size(), kCacheFileFixedBytes + std::string("slices").size() + 3 + optionsBytes + 8 * 4 +
                              4 * 3 * 4 * 256 + kCacheFileChecksumBytes);
  EXPECT_EQ(bytes.substr(0, 7), "HCCACHE");
  expectSameTable(decodeSliceTable(bytes, options, "key"), table);
  EXPECT_THROW(decodeSliceTable(bytes, options, "other"), std::runtime_error);
  EXPECT_THROW(decodeSliceTable(bytes.substr(0, 20), options, "key"), std::runtime_error);
  SliceTableOptions other = options;
  other.level = 5;
  EXPECT_THROW(decodeSliceTable(bytes, other, "key"), std::runtime_error);
  EXPECT_THROW(encodeSliceTable(table, other, "key"), std::invalid_argument);
}

TEST(SliceCache, FileKeyChangesWhenTheFileDoes) {
  TempDir dir(kTempPrefix);
  const fs::path file = dir / "material.binary";
  std::ofstream(file) << "first";
  const std::string before = fileCacheKey(file.string());
  EXPECT_NE(before.find(fs::canonical(file).string()), std::string::npos);
  std::ofstream(file) << "second, longer";
  EXPECT_NE(fileCacheKey(file.string()), before);
  EXPECT_THROW(fileCacheKey((dir / "missing").string()), std::runtime_error);
}

TEST(BrdfSliceTableFromSlices, ValidatesWhatItIsGiven) {
  const BrdfSliceTable table = BrdfSliceTable::build(*testBrdf(), smallOptions());
  std::vector<double> theta;
  std::vector<HaarMap> slices;
  for (int t = 0; t < 4; ++t) theta.push_back(table.thetaOut(t));
  for (int c = 0; c < 3; ++c) {
    for (int t = 0; t < 4; ++t) slices.push_back(table.slice(c, t));
  }
  expectSameTable(BrdfSliceTable::fromSlices(theta, slices), table);

  EXPECT_THROW(BrdfSliceTable::fromSlices({}, {}), std::invalid_argument);
  EXPECT_THROW(BrdfSliceTable::fromSlices(theta, std::vector<HaarMap>(slices.begin(), slices.end() - 1)),
               std::invalid_argument);
  std::vector<double> shifted = theta;
  shifted[2] += 0.01;
  EXPECT_THROW(BrdfSliceTable::fromSlices(shifted, slices), std::invalid_argument);
  std::vector<HaarMap> mixed = slices;
  mixed[5] = HaarMap(3);
  EXPECT_THROW(BrdfSliceTable::fromSlices(theta, mixed), std::invalid_argument);
  std::vector<HaarMap> nan = slices;
  nan[7][3] = std::nanf("");
  EXPECT_THROW(BrdfSliceTable::fromSlices(theta, nan), std::invalid_argument);
}

TEST(SliceCache, HitIsMuchFasterThanBuild) {
  // The figure for the report: level 6, 16 slices, 4² samples per pixel.
  TempDir dir(kTempPrefix);
  const auto brdf = makeGgx({0.05, 0.05, 0.05}, {0.9, 0.6, 0.3}, 0.2);
  SliceTableOptions options;
  options.level = 6;
  options.thetaSamples = 16;
  options.supersampling = 4;
  const auto t0 = std::chrono::steady_clock::now();
  const Call built = cached(*brdf, options, dir.path(), "ggx");
  const auto t1 = std::chrono::steady_clock::now();
  const Call hit = cached(*brdf, options, dir.path(), "ggx");
  const auto t2 = std::chrono::steady_clock::now();
  ASSERT_TRUE(hit.status.hit);
  const double buildMs = std::chrono::duration<double, std::milli>(t1 - t0).count();
  const double hitMs = std::chrono::duration<double, std::milli>(t2 - t1).count();
  std::cout << "[ timing   ] slice table level 6, T 16, 4x4 (" << built.table.storedBytes() / 1024
            << " KiB): build + write " << buildMs << " ms, cache hit " << hitMs << " ms\n";
  EXPECT_LT(hitMs, buildMs);
}

}  // namespace
}  // namespace haarcast::io
