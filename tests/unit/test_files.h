// Scaffolding the unit tests share for files on disk: a fresh temporary
// directory per test, and whole-file writes and reads in binary mode.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>

namespace haarcast::testing {

namespace fs = std::filesystem;

// A fresh directory under fs::temp_directory_path(), named prefix + a
// steady_clock count + "-" + a counter, removed (errors ignored) afterwards.
class TempDir {
 public:
  explicit TempDir(std::string prefix) {
    static std::atomic<int> counter{0};
    path_ = fs::temp_directory_path() /
            (std::move(prefix) + std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()) + "-" +
             std::to_string(counter++));
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  fs::path operator/(const std::string& name) const { return path_ / name; }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// Writes `bytes` to `path` in binary mode, replacing what was there, and
// returns the path as a string. Errors are not reported: a test that cares
// checks the file afterwards.
inline std::string writeFile(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path.string();
}

// The whole of `path`, read in binary mode; fs::file_size throws
// fs::filesystem_error when the file is absent.
inline std::string readFile(const fs::path& path) {
  // Sized from the file, not an istreambuf_iterator (GCC 12 flags a false
  // -Wnull-dereference inside it).
  std::string bytes(static_cast<std::size_t>(fs::file_size(path)), '\0');
  std::ifstream(path, std::ios::binary).read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return bytes;
}

}  // namespace haarcast::testing
