#include "app_paths.h"

#include <cstdlib>
#include <system_error>

namespace haarcast::app {

namespace fs = std::filesystem;

std::string defaultCacheDir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return (fs::path(xdg) / "haarcast").string();
  if (const char* home = std::getenv("HOME"); home && *home) return (fs::path(home) / ".cache" / "haarcast").string();
  return ".haarcast-cache";
}

std::string cacheDirFromFlag(const std::string& flag) {
  if (flag.empty()) return defaultCacheDir();
  return flag == "none" ? std::string() : flag;
}

fs::path executableDir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::current_path() : exe.parent_path();
}

fs::path findShipped(const fs::path& relative, const std::vector<fs::path>& installed) {
  std::error_code ec;
  const fs::path source = fs::path(HAARCAST_SOURCE_DIR) / relative;
  if (fs::exists(source, ec)) return source;
  for (const auto& candidate : installed) {
    const fs::path p = executableDir() / candidate;
    if (fs::exists(p, ec)) return fs::weakly_canonical(p, ec);
  }
  return {};
}

}  // namespace haarcast::app
