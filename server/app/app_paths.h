// Where the `haarcast` commands find their files: the cache folder, and the
// files the project ships beside the binary (the browser client, the
// .proto, the report's plot script).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace haarcast::app {

// $XDG_CACHE_HOME/haarcast, else ~/.cache/haarcast, else .haarcast-cache.
std::string defaultCacheDir();

// A --cache-dir flag: empty = defaultCacheDir(), "none" = no cache (""),
// anything else as given.
std::string cacheDirFromFlag(const std::string& flag);

// The source tree's copy of `relative` (a build folder's binary), else the
// first of `installed` (relative to the executable's folder, e.g.
// "../share/haarcast/web" for <prefix>/bin/haarcast) that exists; empty when
// none does.
std::filesystem::path findShipped(const std::filesystem::path& relative,
                                  const std::vector<std::filesystem::path>& installed);

// The folder of the running executable (the working folder if unknown).
std::filesystem::path executableDir();

}  // namespace haarcast::app
