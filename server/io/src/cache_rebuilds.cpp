#include "haarcast/io/cache_rebuilds.h"

#include <atomic>
#include <iostream>
#include <mutex>
#include <unordered_set>

namespace haarcast::io {
namespace {

// Paths already logged; past this many, rebuilds are still counted but no
// longer logged one by one (a cache directory of damaged files must not
// turn into a log flood).
constexpr std::size_t kMaxLoggedPaths = 4096;

std::atomic<std::uint64_t> counts[3];

bool startsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

}  // namespace

std::string_view cacheRebuildReasonName(CacheRebuildReason reason) {
  switch (reason) {
    case CacheRebuildReason::Corrupt: return "corrupt";
    case CacheRebuildReason::Stale: return "stale";
    case CacheRebuildReason::Unreadable: return "unreadable";
  }
  return "?";
}

std::optional<CacheRebuildReason> classifyCacheMiss(std::string_view whyNot) {
  // The reasons cache_file.cpp gives, by their first words.
  if (whyNot.empty() || whyNot == "no cache file") return std::nullopt;
  for (std::string_view stale : {"container format version", "version ", "kind differs", "the file was built from",
                                 "options differ"}) {
    if (startsWith(whyNot, stale)) return CacheRebuildReason::Stale;
  }
  if (startsWith(whyNot, "cannot ") || startsWith(whyNot, "the cache path is not")) return CacheRebuildReason::Unreadable;
  return CacheRebuildReason::Corrupt;
}

void noteCacheRebuild(CacheRebuildReason reason, const std::string& path, const std::string& why) {
  counts[static_cast<int>(reason)].fetch_add(1);
  if (reason == CacheRebuildReason::Stale) return;
  static std::mutex mutex;
  static std::unordered_set<std::string> logged;
  std::lock_guard lock(mutex);
  if (logged.size() >= kMaxLoggedPaths || !logged.insert(path).second) return;
  std::cerr << "haarcast: warning: cache file " << path << " is " << cacheRebuildReasonName(reason) << " (" << why
            << "): rebuilding it\n";
}

std::uint64_t cacheRebuilds(CacheRebuildReason reason) { return counts[static_cast<int>(reason)].load(); }

}  // namespace haarcast::io
