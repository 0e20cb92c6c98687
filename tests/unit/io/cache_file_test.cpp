// The cache file container: a written file reads back as its payload; every
// way a file can be stale or damaged (other kind, version, key or options, a
// flipped byte anywhere, a cut-off, grown, empty or garbage file) is a miss
// with a reason and never a crash; writes are atomic, even with concurrent
// writers; and a cache that cannot be written is an error value, not a throw
// from the store.
#include "haarcast/io/cache_file.h"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "../test_files.h"

namespace haarcast::io {
namespace {

namespace fs = std::filesystem;
using haarcast::testing::readFile;
using haarcast::testing::TempDir;
using haarcast::testing::writeFile;

constexpr const char* kTempPrefix = "haarcast-cache-file-test-";

CacheHeader testHeader() { return CacheHeader{"test", 3, "some/file|123|456", "level=4 supersampling=2"}; }

// Binary on purpose: NULs and high bytes must survive.
std::string testPayload() {
  std::string p;
  for (int i = 0; i < 300; ++i) p.push_back(static_cast<char>((i * 37) & 0xff));
  return p;
}

std::size_t filesIn(const fs::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++n;
  return n;
}

// The reason readCacheFile gives for `bytes` on disk under `expected`; it
// must be a miss.
std::string missReason(const fs::path& path, const std::string& bytes, const CacheHeader& expected) {
  writeFile(path, bytes);
  std::string why;
  const std::optional<std::string> payload = readCacheFile(path.string(), expected, &why);
  EXPECT_FALSE(payload.has_value()) << "a hit, expected a miss";
  EXPECT_FALSE(why.empty()) << "a miss without a reason";
  // The in-memory decoder must agree.
  std::string whyInMemory;
  EXPECT_FALSE(decodeCacheFile(bytes, expected, &whyInMemory).has_value());
  EXPECT_FALSE(whyInMemory.empty());
  return why;
}

TEST(CacheFile, WriteThenReadGivesThePayloadBack) {
  TempDir tmp(kTempPrefix);
  const fs::path dir = tmp / "nested" / "cache";  // created by the write
  const fs::path path = dir / cacheFileName("test", "k", "o");
  writeCacheFile(path.string(), testHeader(), testPayload());
  EXPECT_EQ(filesIn(dir), 1u) << "a temporary file was left behind";

  std::string why = "unset";
  const std::optional<std::string> payload = readCacheFile(path.string(), testHeader(), &why);
  ASSERT_TRUE(payload.has_value()) << why;
  EXPECT_EQ(*payload, testPayload());
  EXPECT_TRUE(why.empty());

  // The bytes on disk are the documented layout.
  const std::string bytes = readFile(path);
  const CacheHeader h = testHeader();
  EXPECT_EQ(bytes.size(), kCacheFileFixedBytes + h.kind.size() + h.key.size() + h.optionsText.size() +
                              testPayload().size() + kCacheFileChecksumBytes);
  EXPECT_EQ(bytes.substr(0, 8), std::string("HCCACHE\0", 8));
  EXPECT_EQ(bytes.substr(kCacheFileFixedBytes, h.kind.size()), "test");
  const std::optional<std::string_view> inMemory = decodeCacheFile(bytes, h);
  ASSERT_TRUE(inMemory.has_value());
  EXPECT_EQ(*inMemory, testPayload());

  // Rewriting replaces the file whole.
  writeCacheFile(path.string(), testHeader(), "shorter");
  EXPECT_EQ(readCacheFile(path.string(), testHeader()).value_or("miss"), "shorter");
  EXPECT_EQ(filesIn(dir), 1u);
}

TEST(CacheFile, EmptyPayloadAndEmptyTextsRoundTrip) {
  const CacheHeader h{"k", 0, "", ""};
  const std::string bytes = encodeCacheFile(h, "");
  EXPECT_EQ(bytes.size(), kCacheFileFixedBytes + 1 + kCacheFileChecksumBytes);
  const auto payload = decodeCacheFile(bytes, h);
  ASSERT_TRUE(payload.has_value());
  EXPECT_TRUE(payload->empty());
}

TEST(CacheFile, EveryMismatchIsAMissWithAReason) {
  TempDir tmp(kTempPrefix);
  const fs::path path = tmp / "entry.hccache";
  const CacheHeader h = testHeader();
  const std::string good = encodeCacheFile(h, testPayload());
  const std::size_t payloadAt = kCacheFileFixedBytes + h.kind.size() + h.key.size() + h.optionsText.size();
  const auto flipped = [&](std::size_t offset) {
    std::string b = good;
    b[offset] = static_cast<char>(b[offset] ^ 0x5a);
    return b;
  };
  const auto expecting = [&](auto change) {
    CacheHeader other = h;
    change(other);
    return other;
  };
  struct Case {
    std::string label;
    std::string bytes;
    CacheHeader expected;
    std::string reason;
  };
  std::mt19937 random(7);
  std::string garbage(1000, '\0');
  for (char& c : garbage) c = static_cast<char>(random());
  const std::vector<Case> cases = {
      {"another kind", good, expecting([](CacheHeader& e) { e.kind = "slices"; }), "kind differs"},
      {"another version", good, expecting([](CacheHeader& e) { e.version = 4; }), "version 3 of the test cache"},
      {"another key", good, expecting([](CacheHeader& e) { e.key += "x"; }), "another key"},
      {"other options", good, expecting([](CacheHeader& e) { e.optionsText = "level=5 supersampling=2"; }),
       "options differ"},
      {"a payload byte flipped", flipped(payloadAt + 17), h, "checksum mismatch"},
      {"a checksum byte flipped", flipped(good.size() - 3), h, "checksum mismatch"},
      {"the container version flipped", flipped(8), h, "container format version"},
      {"the magic flipped", flipped(2), h, "bad magic"},
      {"cut short by a byte", good.substr(0, good.size() - 1), h, "wrong size"},
      {"cut inside the header", good.substr(0, 20), h, "wrong size"},
      {"grown by a byte", good + "x", h, "wrong size"},
      {"empty", "", h, "empty file"},
      {"garbage", garbage, h, "bad magic"},
      {"garbage behind the magic", std::string("HCCACHE\0", 8) + garbage, h, ""},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.label);
    const std::string why = missReason(path, c.bytes, c.expected);
    EXPECT_NE(why.find(c.reason), std::string::npos) << why;
  }
  std::string why;
  EXPECT_FALSE(readCacheFile((tmp / "absent").string(), h, &why).has_value());
  EXPECT_EQ(why, "no cache file");
  EXPECT_FALSE(readCacheFile(tmp.path().string(), h, &why).has_value());
  EXPECT_NE(why.find("not a regular file"), std::string::npos) << why;
}

TEST(CacheFile, NoFlippedByteOrTruncationIsEverAHit) {
  // Exhaustive over a small file: each of 8 bit patterns at every offset, and
  // every proper prefix. Run under the sanitizers this is also the proof that
  // no header value makes the reader step outside the bytes.
  const CacheHeader h{"t", 1, "key", "opts"};
  const std::string good = encodeCacheFile(h, "payload bytes");
  for (std::size_t offset = 0; offset < good.size(); ++offset) {
    for (const unsigned char mask : {0x01, 0x02, 0x10, 0x80, 0x5a, 0xff, 0x7f, 0xfe}) {
      std::string bad = good;
      bad[offset] = static_cast<char>(static_cast<unsigned char>(bad[offset]) ^ mask);
      std::string why;
      EXPECT_FALSE(decodeCacheFile(bad, h, &why).has_value()) << "offset " << offset << " mask " << int{mask};
      EXPECT_FALSE(why.empty());
    }
  }
  for (std::size_t size = 0; size < good.size(); ++size) {
    std::string why;
    EXPECT_FALSE(decodeCacheFile(std::string_view(good).substr(0, size), h, &why).has_value()) << size;
    EXPECT_FALSE(why.empty());
  }
}

TEST(CacheFile, HugeDeclaredLengthsAreRefusedBeforeReading) {
  // A header claiming a 2⁶⁴−1-byte payload or a 4 GiB key on a small file.
  const CacheHeader h{"t", 1, "key", "opts"};
  std::string bad = encodeCacheFile(h, "x");
  for (std::size_t i = 28; i < 36; ++i) bad[i] = '\xff';
  std::string why;
  EXPECT_FALSE(decodeCacheFile(bad, h, &why).has_value());
  EXPECT_NE(why.find("wrong size"), std::string::npos) << why;
  bad = encodeCacheFile(h, "x");
  for (std::size_t i = 20; i < 24; ++i) bad[i] = '\xff';
  EXPECT_FALSE(decodeCacheFile(bad, h, &why).has_value());
  EXPECT_NE(why.find("over"), std::string::npos) << why;
}

TEST(CacheFile, BadHeadersAreRefusedOnWrite) {
  EXPECT_THROW(encodeCacheFile(CacheHeader{"", 1, "k", "o"}, ""), std::invalid_argument);
  EXPECT_THROW(encodeCacheFile(CacheHeader{"../up", 1, "k", "o"}, ""), std::invalid_argument);
  EXPECT_THROW(encodeCacheFile(CacheHeader{"Slices", 1, "k", "o"}, ""), std::invalid_argument);
  EXPECT_THROW(encodeCacheFile(CacheHeader{"s", 1, std::string(kMaxCacheText + 1, 'k'), "o"}, ""),
               std::invalid_argument);
  EXPECT_THROW(encodeCacheFile(CacheHeader{"s", 1, "k", std::string(kMaxCacheText + 1, 'o')}, ""),
               std::invalid_argument);
  EXPECT_NO_THROW(encodeCacheFile(CacheHeader{"s", 1, std::string(kMaxCacheText, 'k'), "o"}, ""));
  EXPECT_THROW(cacheFileName("a/b", "k", "o"), std::invalid_argument);
}

TEST(CacheFile, NamesAreHashedFromKindKeyAndOptions) {
  const std::string name = cacheFileName("visibility", "k", "o");
  EXPECT_TRUE(std::regex_match(name, std::regex("visibility-[0-9a-f]{16}-[0-9a-f]{16}\\.hccache"))) << name;
  EXPECT_EQ(name, cacheFileName("visibility", "k", "o"));
  EXPECT_NE(name, cacheFileName("slices", "k", "o"));
  EXPECT_NE(name, cacheFileName("visibility", "k2", "o"));
  EXPECT_NE(name, cacheFileName("visibility", "k", "o2"));
  // One key's entries share a prefix.
  EXPECT_EQ(name.substr(0, 28), cacheFileName("visibility", "k", "o2").substr(0, 28));
}

TEST(CacheFile, Fnv1a64MatchesTheReferenceValues) {
  // From the FNV reference test suite (Noll).
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ull);
  // Chaining is the same as hashing the concatenation.
  EXPECT_EQ(fnv1a64("bar", fnv1a64("foo")), fnv1a64("foobar"));
}

TEST(CacheFile, PayloadReaderNeverReadsPastTheEnd) {
  std::string bytes;
  appendLittleEndian<std::uint32_t>(bytes, 0x01020304u);
  appendLittleEndian<float>(bytes, 1.5f);
  EXPECT_EQ(bytes.substr(0, 4), std::string("\x04\x03\x02\x01", 4));
  PayloadReader in(bytes);
  EXPECT_EQ(in.take<std::uint32_t>(), 0x01020304u);
  EXPECT_THROW(in.take<double>(), std::runtime_error);
  EXPECT_EQ(in.take<float>(), 1.5f);
  EXPECT_EQ(in.remaining(), 0u);
  EXPECT_THROW(in.take<std::uint8_t>(), std::runtime_error);
  EXPECT_THROW(in.takeBytes(1), std::runtime_error);
}

TEST(CacheFile, AnUnusableDirectoryIsAnErrorNotACrash) {
  TempDir tmp(kTempPrefix);
  // A regular file where the directory should be: fails even for root, which
  // permission bits would not stop.
  const fs::path blocker = tmp / "not-a-directory";
  std::ofstream(blocker) << "x";
  EXPECT_THROW(writeCacheFile((blocker / "cache" / "f.hccache").string(), testHeader(), "p"), std::runtime_error);
  EXPECT_THROW(writeCacheFile((blocker / "f.hccache").string(), testHeader(), "p"), std::runtime_error);

  CacheStatus status;
  EXPECT_NO_THROW(storeCacheEntry((blocker / "cache").string(), testHeader(), "p", status, false));
  EXPECT_FALSE(status.written);
  EXPECT_FALSE(status.error.empty());
  CacheStatus looked;
  EXPECT_FALSE(lookUpCacheEntry((blocker / "cache").string(), testHeader(), looked).has_value());
  EXPECT_EQ(looked.reason, "no cache file");
  EXPECT_FALSE(looked.hit);
}

TEST(CacheFile, LookUpFindsWhatStoreWrote) {
  TempDir tmp(kTempPrefix);
  CacheStatus first;
  EXPECT_FALSE(lookUpCacheEntry(tmp.path().string(), testHeader(), first).has_value());
  EXPECT_EQ(first.reason, "no cache file");
  storeCacheEntry(tmp.path().string(), testHeader(), testPayload(), first, false);
  EXPECT_TRUE(first.written);
  EXPECT_TRUE(first.error.empty()) << first.error;
  EXPECT_EQ(fs::path(first.path).filename(), cacheFileName("test", testHeader().key, testHeader().optionsText));

  CacheStatus second;
  const std::optional<std::string> payload = lookUpCacheEntry(tmp.path().string(), testHeader(), second);
  ASSERT_TRUE(payload.has_value()) << second.reason;
  EXPECT_TRUE(second.hit);
  EXPECT_EQ(second.path, first.path);
  EXPECT_EQ(*payload, testPayload());
}

TEST(CacheFile, ConcurrentWritersNeverLeaveAHalfFile) {
  // Writers race on one name with payloads of different sizes while a reader
  // polls it: every read is a miss because the file is not there yet, or one
  // writer's whole payload.
  TempDir tmp(kTempPrefix);
  const std::string path = (tmp / "race.hccache").string();
  const std::string small(1000, 'a'), large(200000, 'b');
  std::atomic<bool> done{false};
  std::atomic<int> torn{0}, hits{0};
  std::thread reader([&] {
    while (!done) {
      std::string why;
      const std::optional<std::string> p = readCacheFile(path, testHeader(), &why);
      if (p) {
        ++hits;
        if (*p != small && *p != large) ++torn;
      } else if (why != "no cache file") {
        ++torn;
      }
    }
  });
  std::vector<std::thread> writers;
  for (int w = 0; w < 2; ++w) {
    writers.emplace_back([&, w] {
      for (int i = 0; i < 10; ++i) writeCacheFile(path, testHeader(), w == 0 ? small : large);
    });
  }
  for (std::thread& t : writers) t.join();
  done = true;
  reader.join();
  EXPECT_EQ(torn.load(), 0);
  EXPECT_TRUE(readCacheFile(path, testHeader()).has_value());
  EXPECT_EQ(filesIn(tmp.path()), 1u);
}

}  // namespace
}  // namespace haarcast::io
