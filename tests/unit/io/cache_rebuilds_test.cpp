// A cache file that is there but unusable is counted by reason and, when it
// is corrupt, logged once with its name.
#include "haarcast/io/cache_rebuilds.h"

#include <gtest/gtest.h>

#include "../test_files.h"
#include "haarcast/io/cache_file.h"

namespace haarcast::io {
namespace {

namespace fs = std::filesystem;
using haarcast::testing::readFile;
using haarcast::testing::TempDir;
using haarcast::testing::writeFile;

TEST(CacheRebuilds, CorruptFilesAreCountedAndLoggedOnceStaleOnesOnlyCounted) {
  TempDir tmp("haarcast-cache-rebuilds-test-");
  const std::string dir = tmp.path().string();
  const CacheHeader header{"test", 1, "key", "options"};
  const auto corrupt0 = cacheRebuilds(CacheRebuildReason::Corrupt);
  const auto stale0 = cacheRebuilds(CacheRebuildReason::Stale);

  CacheStatus status;
  EXPECT_FALSE(lookUpCacheEntry(dir, header, status));  // no file: a first build, not a rebuild
  storeCacheEntry(dir, header, "payload", status, false);
  ASSERT_TRUE(status.written);
  std::string bytes = readFile(status.path);
  bytes[bytes.size() - 10] ^= 0x40;  // a payload byte
  writeFile(status.path, bytes);

  ::testing::internal::CaptureStderr();
  for (int i = 0; i < 3; ++i) {
    CacheStatus again;
    EXPECT_FALSE(lookUpCacheEntry(dir, header, again));
  }
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(cacheRebuilds(CacheRebuildReason::Corrupt), corrupt0 + 3);
  EXPECT_EQ(log, "haarcast: warning: cache file " + status.path +
                     " is corrupt (checksum mismatch (corrupt file)): rebuilding it\n")
      << "one line, naming the file";

  // Another version of the same entry: stale, counted, not logged.
  CacheHeader newer = header;
  newer.version = 2;
  writeFile(status.path, encodeCacheFile(header, "payload"));
  ::testing::internal::CaptureStderr();
  CacheStatus other;
  EXPECT_FALSE(readCacheFile(status.path, newer, &other.reason));
  EXPECT_EQ(classifyCacheMiss(other.reason), CacheRebuildReason::Stale) << other.reason;
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");

  writeFile(status.path, bytes.substr(0, 20));  // truncated
  CacheStatus truncated;
  EXPECT_FALSE(lookUpCacheEntry(dir, header, truncated));
  EXPECT_EQ(cacheRebuilds(CacheRebuildReason::Corrupt), corrupt0 + 4) << truncated.reason;
  EXPECT_EQ(cacheRebuilds(CacheRebuildReason::Stale), stale0);
  EXPECT_EQ(classifyCacheMiss("no cache file"), std::nullopt);
  EXPECT_EQ(classifyCacheMiss("cannot open the cache file"), CacheRebuildReason::Unreadable);
}

}  // namespace
}  // namespace haarcast::io
