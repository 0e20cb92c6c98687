// The `.hcslice` slice-table cache (format in slice_cache.h).
#include "haarcast/io/slice_cache.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <system_error>
#include <utility>
#include <vector>

namespace haarcast::io {
namespace {

namespace fs = std::filesystem;

constexpr std::array<char, 8> kMagic = {'H', 'C', 'S', 'L', 'I', 'C', 'E', '\0'};
constexpr std::size_t kFixedHeaderBytes = 32;
constexpr std::size_t kChecksumBytes = 8;

// FNV-1a, 64-bit (Fowler, Noll, Vo): one multiply per byte, no table, and
// any single flipped byte changes the result. Not cryptographic; it guards
// against torn and corrupted files, not against an adversary.
std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash = 0xcbf29ce484222325ull) {
  for (const char c : bytes) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001b3ull;
  }
  return hash;
}

template <typename T>
void put(std::string& out, T value) {
  std::array<char, sizeof(T)> raw{};
  std::memcpy(raw.data(), &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw.begin(), raw.end());
  out.append(raw.data(), raw.size());
}

template <typename T>
T get(std::string_view bytes, std::size_t offset) {
  std::array<char, sizeof(T)> raw{};
  std::memcpy(raw.data(), bytes.data() + offset, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(raw.begin(), raw.end());
  T value;
  std::memcpy(&value, raw.data(), sizeof(T));
  return value;
}

std::size_t coefficientsPerSlice(int level) {
  return static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
}

// The exact size of a file for these options and key, or 0 if the options
// are out of the range the table builder accepts (checked by the caller).
std::uint64_t expectedFileBytes(const SliceTableOptions& options, std::size_t keyBytes) {
  const std::uint64_t t = static_cast<std::uint64_t>(options.thetaSamples);
  return kFixedHeaderBytes + keyBytes + 8 * t +
         4 * static_cast<std::uint64_t>(BrdfSliceTable::kChannels) * t * coefficientsPerSlice(options.level) +
         kChecksumBytes;
}

[[noreturn]] void mismatch(const std::string& what) { throw std::runtime_error(what); }

void report(SliceCacheStatus& status, bool toStderr, const std::string& error) {
  if (!status.error.empty()) status.error += "; ";
  status.error += error;
  if (toStderr) std::cerr << "haarcast: warning: slice cache: " << error << " (the table is built, not cached)\n";
}

// Writes `bytes` to `path` through a temporary file in the same directory and
// a rename, which POSIX makes atomic: a reader sees the old file or the whole
// new one. fsync before the rename so that after a power loss the name never
// points at blocks that were not written. Throws std::runtime_error.
void writeAtomically(const fs::path& path, std::string_view bytes) {
  static std::atomic<unsigned> counter{0};
  const fs::path temp = path.string() + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot create " + temp.string() + ": " + std::strerror(errno));
  const auto failWith = [&](const std::string& what) {
    const int err = errno;
    ::close(fd);
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw std::runtime_error(what + " " + temp.string() + ": " + std::strerror(err));
  };
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      failWith("cannot write");
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) failWith("cannot sync");
  if (::close(fd) != 0) {
    const int err = errno;
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw std::runtime_error("cannot close " + temp.string() + ": " + std::strerror(err));
  }
  std::error_code ec;
  fs::rename(temp, path, ec);
  if (ec) {
    std::error_code ignored;
    fs::remove(temp, ignored);
    throw std::runtime_error("cannot rename " + temp.string() + " to " + path.string() + ": " + ec.message());
  }
}

}  // namespace

std::string sliceCacheFileName(const std::string& key, const SliceTableOptions& options) {
  char hash[17];
  std::snprintf(hash, sizeof hash, "%016llx", static_cast<unsigned long long>(fnv1a64(key)));
  return std::string("slices-") + hash + "-l" + std::to_string(options.level) + "-t" +
         std::to_string(options.thetaSamples) + "-s" + std::to_string(options.supersampling) + ".hcslice";
}

std::string fileCacheKey(const std::string& path) {
  std::error_code ec;
  const fs::path canonical = fs::canonical(path, ec);
  if (ec) throw std::runtime_error(path + ": cannot make a cache key: " + ec.message());
  const std::uintmax_t size = fs::file_size(canonical, ec);
  if (ec) throw std::runtime_error(path + ": cannot make a cache key: " + ec.message());
  const fs::file_time_type mtime = fs::last_write_time(canonical, ec);
  if (ec) throw std::runtime_error(path + ": cannot make a cache key: " + ec.message());
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(mtime.time_since_epoch()).count();
  return canonical.string() + "|" + std::to_string(size) + "|" + std::to_string(ns);
}

std::string encodeSliceTable(const BrdfSliceTable& table, const SliceTableOptions& options, const std::string& key) {
  if (table.level() != options.level || table.thetaSamples() != options.thetaSamples) {
    throw std::invalid_argument("encodeSliceTable: the table has level " + std::to_string(table.level()) + " and " +
                                std::to_string(table.thetaSamples()) + " slices, the options say level " +
                                std::to_string(options.level) + " and " + std::to_string(options.thetaSamples));
  }
  if (key.size() > kMaxSliceCacheKey) {
    throw std::invalid_argument("encodeSliceTable: key of " + std::to_string(key.size()) + " bytes is over " +
                                std::to_string(kMaxSliceCacheKey));
  }
  std::string out;
  out.reserve(static_cast<std::size_t>(expectedFileBytes(options, key.size())));
  out.append(kMagic.data(), kMagic.size());
  put<std::uint32_t>(out, kSliceCacheVersion);
  put<std::int32_t>(out, options.level);
  put<std::int32_t>(out, options.thetaSamples);
  put<std::int32_t>(out, options.supersampling);
  put<std::int32_t>(out, BrdfSliceTable::kChannels);
  put<std::uint32_t>(out, static_cast<std::uint32_t>(key.size()));
  out += key;
  for (int t = 0; t < table.thetaSamples(); ++t) put<double>(out, table.thetaOut(t));
  for (int c = 0; c < BrdfSliceTable::kChannels; ++c) {
    for (int t = 0; t < table.thetaSamples(); ++t) {
      const std::span<const float> coeffs = table.slice(c, t).coefficients();
      if constexpr (std::endian::native == std::endian::little) {
        out.append(reinterpret_cast<const char*>(coeffs.data()), coeffs.size_bytes());
      } else {
        for (const float v : coeffs) put<float>(out, v);
      }
    }
  }
  put<std::uint64_t>(out, fnv1a64(out));
  return out;
}

BrdfSliceTable decodeSliceTable(std::string_view bytes, const SliceTableOptions& options, const std::string& key) {
  if (bytes.size() < kFixedHeaderBytes + kChecksumBytes) {
    mismatch("truncated: " + std::to_string(bytes.size()) + " bytes is less than a header");
  }
  if (!std::equal(kMagic.begin(), kMagic.end(), bytes.begin())) mismatch("not a slice cache file (bad magic)");
  const auto version = get<std::uint32_t>(bytes, 8);
  if (version != kSliceCacheVersion) {
    mismatch("format version " + std::to_string(version) + ", this build reads " + std::to_string(kSliceCacheVersion));
  }
  const auto level = get<std::int32_t>(bytes, 12);
  const auto thetaSamples = get<std::int32_t>(bytes, 16);
  const auto supersampling = get<std::int32_t>(bytes, 20);
  const auto channels = get<std::int32_t>(bytes, 24);
  const auto keyBytes = get<std::uint32_t>(bytes, 28);
  if (level != options.level || thetaSamples != options.thetaSamples || supersampling != options.supersampling ||
      channels != BrdfSliceTable::kChannels) {
    mismatch("options differ: file has level " + std::to_string(level) + ", " + std::to_string(thetaSamples) +
             " slices, supersampling " + std::to_string(supersampling) + ", " + std::to_string(channels) +
             " channels; asked for level " + std::to_string(options.level) + ", " +
             std::to_string(options.thetaSamples) + " slices, supersampling " + std::to_string(options.supersampling));
  }
  if (keyBytes != key.size() || bytes.size() < kFixedHeaderBytes + keyBytes ||
      bytes.substr(kFixedHeaderBytes, keyBytes) != key) {
    mismatch("the file was built from another key");
  }
  if (level < 0 || level > kMaxLevel || thetaSamples < 1) {
    mismatch("level " + std::to_string(level) + " or thetaSamples " + std::to_string(thetaSamples) +
             " is out of range");
  }
  const std::uint64_t expected = expectedFileBytes(options, key.size());
  if (bytes.size() != expected) {
    mismatch((bytes.size() < expected ? "truncated: " : "wrong size: ") + std::to_string(bytes.size()) +
             " bytes, expected " + std::to_string(expected));
  }
  const std::size_t body = bytes.size() - kChecksumBytes;
  if (fnv1a64(bytes.substr(0, body)) != get<std::uint64_t>(bytes, body)) mismatch("checksum mismatch (corrupt file)");

  const std::size_t t = static_cast<std::size_t>(thetaSamples);
  std::size_t offset = kFixedHeaderBytes + keyBytes;
  std::vector<double> thetaOut(t);
  for (std::size_t i = 0; i < t; ++i, offset += 8) thetaOut[i] = get<double>(bytes, offset);
  std::vector<HaarMap> slices;
  slices.reserve(BrdfSliceTable::kChannels * t);
  const std::size_t count = coefficientsPerSlice(level);
  for (std::size_t s = 0; s < BrdfSliceTable::kChannels * t; ++s) {
    HaarMap map(level);
    const std::span<float> coeffs = map.coefficients();
    if constexpr (std::endian::native == std::endian::little) {
      std::memcpy(coeffs.data(), bytes.data() + offset, count * sizeof(float));
      offset += count * sizeof(float);
    } else {
      for (std::size_t k = 0; k < count; ++k, offset += 4) coeffs[k] = get<float>(bytes, offset);
    }
    slices.push_back(std::move(map));
  }
  try {
    return BrdfSliceTable::fromSlices(std::move(thetaOut), std::move(slices));
  } catch (const std::invalid_argument& e) {
    mismatch(std::string("invalid contents: ") + e.what());
  }
}

BrdfSliceTable loadOrBuildSliceTable(const Brdf& brdf, const SliceTableOptions& options, const std::string& cacheDir,
                                     const std::string& key, std::function<void(int, int)> progress,
                                     SliceCacheStatus* statusOut) {
  SliceCacheStatus local;
  SliceCacheStatus& status = statusOut ? *statusOut : local;
  status = SliceCacheStatus{};
  const bool toStderr = statusOut == nullptr;

  // Options the builder refuses are its error to report, before any size is
  // computed from them.
  if (options.level < 0 || options.level > kMaxLevel || options.thetaSamples < 1 || options.supersampling < 1) {
    return BrdfSliceTable::build(brdf, options, progress);
  }

  const fs::path path = fs::path(cacheDir) / sliceCacheFileName(key, options);
  status.path = path.string();

  // Look: any failure to read or any mismatch is a miss.
  std::error_code ec;
  if (key.size() > kMaxSliceCacheKey) {
    status.reason = "key too long to store";
  } else if (!fs::exists(path, ec)) {
    status.reason = ec ? "cannot look for the cache file: " + ec.message() : "no cache file";
  } else {
    const std::uintmax_t size = fs::file_size(path, ec);
    const std::uint64_t expected = expectedFileBytes(options, key.size());
    if (ec) {
      status.reason = "cannot stat the cache file: " + ec.message();
    } else if (size != expected) {
      // Checked before reading, so a stray huge file is never loaded.
      status.reason = "wrong size: " + std::to_string(size) + " bytes, expected " + std::to_string(expected);
    } else {
      std::string bytes(static_cast<std::size_t>(size), '\0');
      std::ifstream in(path, std::ios::binary);
      if (!in || !in.read(bytes.data(), static_cast<std::streamsize>(size))) {
        status.reason = "cannot read the cache file";
      } else {
        try {
          BrdfSliceTable table = decodeSliceTable(bytes, options, key);
          status.hit = true;
          return table;
        } catch (const std::exception& e) {
          status.reason = e.what();
        }
      }
    }
  }

  BrdfSliceTable table = BrdfSliceTable::build(brdf, options, progress);

  if (key.size() > kMaxSliceCacheKey) {
    report(status, toStderr, "key of " + std::to_string(key.size()) + " bytes is too long to cache");
    return table;
  }
  fs::create_directories(cacheDir, ec);
  if (ec) {
    report(status, toStderr, "cannot create the cache directory " + cacheDir + ": " + ec.message());
    return table;
  }
  try {
    writeAtomically(path, encodeSliceTable(table, options, key));
    status.written = true;
  } catch (const std::exception& e) {
    report(status, toStderr, e.what());
  }
  return table;
}

}  // namespace haarcast::io
