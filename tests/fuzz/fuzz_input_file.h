// The image loaders and the scene loader read paths, not bytes: each fuzz
// input is written to one file per process (in a directory of its own, so a
// scene's relative references resolve beside it and nowhere else) and the
// loader reads it from there.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace haarcast::fuzz {

// The process's directory, removed when the process exits normally (the
// fuzzer's end of run; a crash leaves it, beside the crashing input).
class InputDirectory {
 public:
  InputDirectory() {
    const char* base = std::getenv("TMPDIR");
    path_ = std::filesystem::path(base != nullptr ? base : "/tmp") / ("haarcast-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(path_);
  }
  ~InputDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  InputDirectory(const InputDirectory&) = delete;
  InputDirectory& operator=(const InputDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline std::string inputFile(const std::string& name, const std::uint8_t* data, std::size_t size) {
  static const InputDirectory dir;
  const std::filesystem::path path = dir.path() / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path.string();
}

}  // namespace haarcast::fuzz
