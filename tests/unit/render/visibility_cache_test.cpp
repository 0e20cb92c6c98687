// The visibility cache: a miss computes (with progress) and writes, a hit
// computes nothing and returns the same coefficients bit for bit; a moved
// vertex or any other option is a miss; a damaged payload — even one whose
// checksum was recomputed to match — is a miss, never a crash; and a cache
// that cannot be written never stops the visibility from being computed.
#include "haarcast/render/visibility_cache.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/io/cache_file.h"
#include "haarcast/io/mesh_io.h"

#include "../test_files.h"

namespace haarcast {
namespace {

namespace fs = std::filesystem;
using haarcast::testing::TempDir;

constexpr const char* kTempPrefix = "haarcast-visibility-cache-test-";

// A torus shadows itself, so the maps are not all the same; 128 vertices at
// level 3 keep the whole file under a second.
Mesh testMesh() { return assets::makeTorus(1.0, 0.35, 16, 8); }

VisibilityOptions testOptions() {
  VisibilityOptions o;
  o.level = 3;
  o.supersampling = 2;
  o.keep = 16;
  return o;
}

struct Call {
  std::vector<SparseHaar> visibility;
  VisibilityCacheStatus status;
  std::size_t progressCalls = 0;
};
Call cached(const Mesh& mesh, const VisibilityOptions& options, const fs::path& dir) {
  Call call;
  call.visibility = loadOrComputeVertexVisibility(
      mesh, options, dir.string(), [&](std::size_t, std::size_t) { ++call.progressCalls; }, &call.status);
  return call;
}

void expectSameVisibility(const std::vector<SparseHaar>& a, const std::vector<SparseHaar>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t v = 0; v < a.size(); ++v) {
    ASSERT_EQ(a[v].level, b[v].level) << "vertex " << v;
    ASSERT_EQ(a[v].index, b[v].index) << "vertex " << v;
    ASSERT_EQ(a[v].value.size(), b[v].value.size()) << "vertex " << v;
    ASSERT_EQ(std::memcmp(a[v].value.data(), b[v].value.data(), a[v].value.size() * sizeof(float)), 0)
        << "vertex " << v;
  }
}

TEST(VisibilityCache, MissComputesAndWritesThenHitComputesNothing) {
  TempDir tmp(kTempPrefix);
  const fs::path dir = tmp / "nested" / "cache";  // created on demand
  const Mesh mesh = testMesh();
  const Call first = cached(mesh, testOptions(), dir);
  EXPECT_FALSE(first.status.hit);
  EXPECT_TRUE(first.status.written);
  EXPECT_EQ(first.status.reason, "no cache file");
  EXPECT_TRUE(first.status.error.empty()) << first.status.error;
  EXPECT_GT(first.progressCalls, 0u);
  ASSERT_TRUE(fs::is_regular_file(first.status.path));
  EXPECT_EQ(fs::path(first.status.path).filename().string().rfind("visibility-", 0), 0u);
  expectSameVisibility(first.visibility, computeVertexVisibility(mesh, testOptions()));

  const Call second = cached(mesh, testOptions(), dir);
  EXPECT_TRUE(second.status.hit) << second.status.reason;
  EXPECT_FALSE(second.status.written);
  EXPECT_EQ(second.progressCalls, 0u);
  EXPECT_EQ(second.status.path, first.status.path);
  expectSameVisibility(second.visibility, first.visibility);
}

TEST(VisibilityCache, AMovedVertexIsAMiss) {
  TempDir dir(kTempPrefix);
  Mesh mesh = testMesh();
  ASSERT_TRUE(cached(mesh, testOptions(), dir.path()).status.written);
  const std::string before = meshContentKey(mesh);
  mesh.positions[5].y += 1e-3f;
  EXPECT_NE(meshContentKey(mesh), before);
  const Call moved = cached(mesh, testOptions(), dir.path());
  EXPECT_FALSE(moved.status.hit);
  EXPECT_GT(moved.progressCalls, 0u);
  expectSameVisibility(moved.visibility, computeVertexVisibility(mesh, testOptions()));
  // A changed normal or a re-wound triangle is another mesh too; the name is not.
  Mesh renamed = testMesh();
  renamed.name = "another name";
  EXPECT_EQ(meshContentKey(renamed), meshContentKey(testMesh()));
  Mesh turned = testMesh();
  turned.normals[0] = -turned.normals[0];
  EXPECT_NE(meshContentKey(turned), meshContentKey(testMesh()));
  Mesh rewound = testMesh();
  std::swap(rewound.triangles[0].y, rewound.triangles[0].z);
  EXPECT_NE(meshContentKey(rewound), meshContentKey(testMesh()));
}

TEST(VisibilityCache, EveryOptionChangeIsAMiss) {
  TempDir dir(kTempPrefix);
  const Mesh mesh = testMesh();
  ASSERT_TRUE(cached(mesh, testOptions(), dir.path()).status.written);
  std::vector<VisibilityOptions> others(4, testOptions());
  others[0].level = 4;
  others[1].supersampling = 3;
  others[2].keep = 15;
  others[3].offset = std::nextafter(testOptions().offset, 1.0f);  // one ulp
  for (const VisibilityOptions& o : others) {
    SCOPED_TRACE(visibilityOptionsText(o));
    const Call other = cached(mesh, o, dir.path());
    EXPECT_FALSE(other.status.hit);
    EXPECT_GT(other.progressCalls, 0u);
    EXPECT_TRUE(other.status.written);
    EXPECT_NE(other.status.path, cached(mesh, testOptions(), dir.path()).status.path);
  }
  // Every entry is kept: the first still hits, and each other one does too.
  EXPECT_TRUE(cached(mesh, testOptions(), dir.path()).status.hit);
  for (const VisibilityOptions& o : others) EXPECT_TRUE(cached(mesh, o, dir.path()).status.hit);
}

TEST(VisibilityCache, AnUnwritableDirectoryStillGivesTheVisibility) {
  TempDir tmp(kTempPrefix);
  // A regular file where the directory should be: fails even for root.
  const fs::path blocker = tmp / "not-a-directory";
  std::ofstream(blocker) << "x";
  const Mesh mesh = testMesh();
  const Call call = cached(mesh, testOptions(), blocker / "cache");
  EXPECT_FALSE(call.status.hit);
  EXPECT_FALSE(call.status.written);
  EXPECT_FALSE(call.status.error.empty());
  EXPECT_GT(call.progressCalls, 0u);
  expectSameVisibility(call.visibility, computeVertexVisibility(mesh, testOptions()));
  // Without a status the failure goes to stderr, and still nothing throws.
  EXPECT_NO_THROW(loadOrComputeVertexVisibility(mesh, testOptions(), (blocker / "cache").string()));
  EXPECT_NO_THROW(loadOrComputeVertexVisibility(mesh, testOptions(), blocker.string()));
}

TEST(VisibilityCache, NoDirectoryMeansNoCache) {
  const Call call = cached(testMesh(), testOptions(), "");
  EXPECT_FALSE(call.status.hit);
  EXPECT_FALSE(call.status.written);
  EXPECT_EQ(call.status.reason, "no cache directory");
  EXPECT_GT(call.progressCalls, 0u);
}

TEST(VisibilityCache, BadInputThrowsHitOrMiss) {
  TempDir dir(kTempPrefix);
  VisibilityOptions bad = testOptions();
  bad.keep = 0;
  EXPECT_THROW(loadOrComputeVertexVisibility(testMesh(), bad, dir.path().string()), std::invalid_argument);
  Mesh broken = testMesh();
  ASSERT_TRUE(cached(broken, testOptions(), dir.path()).status.written);
  broken.normals.pop_back();
  EXPECT_THROW(loadOrComputeVertexVisibility(broken, testOptions(), dir.path().string()), std::invalid_argument);
}

// Rewrites the payload of the entry at `path` and gives it a valid checksum:
// what a bug in a writer, not a torn file, would leave.
void replacePayload(const Mesh& mesh, const VisibilityOptions& options, const std::string& path,
                    const std::string& payload) {
  const io::CacheHeader header{"visibility", kVisibilityCacheVersion, meshContentKey(mesh),
                               visibilityOptionsText(options)};
  io::writeCacheFile(path, header, payload);
}

TEST(VisibilityCache, ACheckSummedButInvalidPayloadIsAMissNotACrash) {
  const Mesh mesh = testMesh();
  const VisibilityOptions options = testOptions();
  const std::vector<SparseHaar> good = computeVertexVisibility(mesh, options);
  const std::string payload = encodeVisibilityPayload(good);
  expectSameVisibility(decodeVisibilityPayload(payload, mesh.positions.size(), options), good);
  ASSERT_GT(good[0].size(), 2u);

  // Offsets into the payload: the vertex count, then vertex 0's count and pairs.
  const std::size_t firstCount = 8, firstIndex = 12, secondIndex = 20, firstValue = 16;
  const auto patched = [&](std::size_t offset, auto value) {
    std::string b = payload;
    std::string raw;
    io::appendLittleEndian(raw, value);
    b.replace(offset, raw.size(), raw);
    return b;
  };
  struct Case {
    std::string label;
    std::string bytes;
    std::string reason;
  };
  const std::vector<Case> cases = {
      {"empty", "", "truncated payload"},
      {"cut short", payload.substr(0, payload.size() - 3), "left"},
      {"a byte too many", payload + "x", "after the last vertex"},
      {"another vertex count", patched(0, std::uint64_t{mesh.positions.size() + 1}), "vertices"},
      {"a huge vertex count", patched(0, std::numeric_limits<std::uint64_t>::max()), "vertices"},
      {"more coefficients than kept", patched(firstCount, std::uint32_t{17}), "at most 16"},
      {"a huge coefficient count", patched(firstCount, std::numeric_limits<std::uint32_t>::max()), "at most"},
      {"an index past the map", patched(firstIndex, std::uint32_t{64}), "past the 64"},
      {"indices out of order", patched(secondIndex, good[0].index[0]), "not increasing"},
      {"a NaN", patched(firstValue, std::numeric_limits<float>::quiet_NaN()), "non-finite"},
      {"an infinity", patched(firstValue, std::numeric_limits<float>::infinity()), "non-finite"},
  };
  TempDir dir(kTempPrefix);
  const std::string path = cached(mesh, options, dir.path()).status.path;
  for (const Case& c : cases) {
    SCOPED_TRACE(c.label);
    try {
      decodeVisibilityPayload(c.bytes, mesh.positions.size(), options);
      ADD_FAILURE() << "decoded";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(c.reason), std::string::npos) << e.what();
    }
    // Through the cache: a miss that recomputes and rewrites the file.
    replacePayload(mesh, options, path, c.bytes);
    const Call call = cached(mesh, options, dir.path());
    EXPECT_FALSE(call.status.hit);
    EXPECT_NE(call.status.reason.find(c.reason), std::string::npos) << call.status.reason;
    EXPECT_TRUE(call.status.written);
    expectSameVisibility(call.visibility, good);
    EXPECT_TRUE(cached(mesh, options, dir.path()).status.hit);
  }
}

TEST(VisibilityCache, OptionsTextIsExact) {
  VisibilityOptions o = testOptions();
  o.offset = 1e-4f;
  EXPECT_EQ(visibilityOptionsText(o), "level=3 supersampling=2 keep=16 offset=1e-04");
  VisibilityOptions next = o;
  next.offset = std::nextafter(o.offset, 1.0f);
  EXPECT_NE(visibilityOptionsText(next), visibilityOptionsText(o));
}

TEST(VisibilityCache, HitIsMuchFasterThanComputeOnTheBunny) {
  // The figure for the report: ../shared/data's bunny at level 5. Seconds of
  // ray casting, so only on request.
  if (!std::getenv("HAARCAST_TIMING")) GTEST_SKIP() << "set HAARCAST_TIMING=1 to time the bunny";
  // tests/unit/render/ → the repository → ../shared/data.
  const fs::path file = fs::path(__FILE__).parent_path() / "../../../../shared/data/meshes/bunny.ply";
  if (!fs::exists(file)) GTEST_SKIP() << "no " << file;
  const Mesh mesh = io::loadMesh(file.string());
  VisibilityOptions options;
  options.level = 5;
  TempDir dir(kTempPrefix);
  const auto t0 = std::chrono::steady_clock::now();
  const Call computed = cached(mesh, options, dir.path());
  const auto t1 = std::chrono::steady_clock::now();
  const Call hit = cached(mesh, options, dir.path());
  const auto t2 = std::chrono::steady_clock::now();
  ASSERT_TRUE(hit.status.hit) << hit.status.reason;
  expectSameVisibility(hit.visibility, computed.visibility);
  const double computeMs = std::chrono::duration<double, std::milli>(t1 - t0).count();
  const double hitMs = std::chrono::duration<double, std::milli>(t2 - t1).count();
  std::cout << "[ timing   ] bunny visibility (" << mesh.positions.size() << " vertices, level 5, 2x2, keep "
            << options.keep << ", " << fs::file_size(hit.status.path) / 1024 << " KiB): compute + write "
            << computeMs << " ms, cache hit " << hitMs << " ms\n";
  EXPECT_LT(hitMs, computeMs);
}

}  // namespace
}  // namespace haarcast
