// Cache entries that were on disk but could not be used, so that their
// result was computed again: counted by reason for the service's /metrics
// (haarcast_cache_rebuilds_total{reason}), and logged once per file for the
// ones an operator should hear of. The counters live here, in io, and the
// service reads them: io knows nothing of the network.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace haarcast::io {

enum class CacheRebuildReason {
  Corrupt,     // bad magic, wrong size, checksum mismatch, a payload that does not decode
  Stale,       // another format or cache version, key or options (an upgrade, a hash collision)
  Unreadable,  // there, but not a regular file or not readable
};
inline constexpr CacheRebuildReason kCacheRebuildReasons[] = {CacheRebuildReason::Corrupt, CacheRebuildReason::Stale,
                                                              CacheRebuildReason::Unreadable};
std::string_view cacheRebuildReasonName(CacheRebuildReason reason);  // "corrupt", "stale", "unreadable"

// The reason a readCacheFile miss (its *whyNot) counts as; nullopt for no
// file at all (a first build is not a rebuild) and for a hit ("").
std::optional<CacheRebuildReason> classifyCacheMiss(std::string_view whyNot);

// One entry at `path` computed again for `reason`; `why` says what was
// wrong. Corrupt and unreadable files are logged on stderr, once per path
// for the life of the process ("haarcast: warning: cache file P is
// corrupt (checksum mismatch): rebuilding it"); stale ones only counted.
void noteCacheRebuild(CacheRebuildReason reason, const std::string& path, const std::string& why);

// Rebuilds since the process started.
std::uint64_t cacheRebuilds(CacheRebuildReason reason);

}  // namespace haarcast::io
