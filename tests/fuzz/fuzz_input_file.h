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

namespace haarcast::fuzz {

inline std::string inputFile(const std::string& name, const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path dir = [] {
    const char* base = std::getenv("TMPDIR");
    std::filesystem::path d = std::filesystem::path(base != nullptr ? base : "/tmp") /
                              ("haarcast-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  const std::filesystem::path path = dir / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path.string();
}

}  // namespace haarcast::fuzz
