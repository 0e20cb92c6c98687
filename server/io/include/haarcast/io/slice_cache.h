// The on-disk cache of BRDF slice tables. Building a table evaluates the BRDF
// T·M²·n² times (level 6, 16 slices, 4² samples: 1M pixels × 16); a table read
// back from disk is bit-identical and takes milliseconds.
//
// Files are haarcast cache files (cache_file.h) of kind "slices", version
// kSliceCacheVersion. The options text is
// "level=<n> thetaSamples=<T> supersampling=<s> channels=3"; the payload,
// little-endian, is
//   8T     f64 θₒ of each slice
//   12TM²  f32 Haar coefficients, slice [channel·T + t], each in HaarMap's
//          quadrant layout, row-major
// Anything that does not match what the caller asks for — version, options,
// key, size, checksum — makes the file a miss: the table is rebuilt and the
// file rewritten.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/io/cache_file.h"

namespace haarcast::io {

// 2: the file became a generic cache file (1 had its own header).
inline constexpr std::uint32_t kSliceCacheVersion = 2;
inline constexpr std::size_t kMaxSliceCacheKey = kMaxCacheText;

// What loadOrBuildSliceTable did, for callers that log or test it: hit means
// nothing was built, written that a built table was stored.
using SliceCacheStatus = CacheStatus;

// Returns the table for (brdf, options), from `cacheDir` when a valid file for
// (key, options) is there, else built (progress as in BrdfSliceTable::build)
// and then written there for next time. The directory is created if missing.
// The cache never makes this fail: when the directory or the file cannot be
// read or written the table is built all the same, and the failure goes to
// status->error, or to one line on stderr when no status is asked for.
// Errors of the build itself (bad options) propagate.
//
// `key` must change whenever the BRDF does: for a file, fileCacheKey(path);
// for an analytic BRDF, its name and parameters. The file is named from a
// hash of the key and the options, so several levels of one material are
// kept side by side; the key is also stored in the file and compared, so a
// hash collision is a miss, never a wrong table. Writes go to a temporary
// file in the same directory which is then renamed over the final name, so a
// crash or a concurrent writer never leaves a half-written file to be read.
BrdfSliceTable loadOrBuildSliceTable(const Brdf& brdf, const SliceTableOptions& options, const std::string& cacheDir,
                                     const std::string& key, std::function<void(int, int)> progress = {},
                                     SliceCacheStatus* status = nullptr);

// "<canonical path>|<size in bytes>|<mtime in ns>": a key that changes when the
// file is replaced or rewritten. Throws std::runtime_error if it cannot be stat'ed.
std::string fileCacheKey(const std::string& path);

// The cache file's name (no directory) for a key and options.
std::string sliceCacheFileName(const std::string& key, const SliceTableOptions& options);

// The file's bytes, as above. options.level and thetaSamples must match the
// table (std::invalid_argument otherwise); supersampling is recorded as given.
std::string encodeSliceTable(const BrdfSliceTable& table, const SliceTableOptions& options, const std::string& key);
// The table in `bytes` if it is a valid file for exactly these options and
// key; otherwise throws std::runtime_error saying what did not match.
BrdfSliceTable decodeSliceTable(std::string_view bytes, const SliceTableOptions& options, const std::string& key);

}  // namespace haarcast::io
