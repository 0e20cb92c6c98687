// The slice-table cache: a "slices" cache file (cache_file.h) whose payload
// is the table (layout in slice_cache.h).
#include "haarcast/io/slice_cache.h"

#include "haarcast/io/cache_rebuilds.h"

#include <bit>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <optional>
#include <span>
#include <stdexcept>
#include <system_error>
#include <utility>
#include <vector>

namespace haarcast::io {
namespace {

namespace fs = std::filesystem;

constexpr const char* kKind = "slices";

std::size_t coefficientsPerSlice(int level) {
  return static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
}

std::string optionsText(const SliceTableOptions& options) {
  return "level=" + std::to_string(options.level) + " thetaSamples=" + std::to_string(options.thetaSamples) +
         " supersampling=" + std::to_string(options.supersampling) +
         " channels=" + std::to_string(BrdfSliceTable::kChannels);
}

CacheHeader header(const SliceTableOptions& options, const std::string& key) {
  return CacheHeader{kKind, kSliceCacheVersion, key, optionsText(options)};
}

std::string encodePayload(const BrdfSliceTable& table) {
  std::string out;
  const std::size_t t = static_cast<std::size_t>(table.thetaSamples());
  out.reserve(8 * t + 4 * BrdfSliceTable::kChannels * t * coefficientsPerSlice(table.level()));
  for (int i = 0; i < table.thetaSamples(); ++i) appendLittleEndian<double>(out, table.thetaOut(i));
  for (int c = 0; c < BrdfSliceTable::kChannels; ++c) {
    for (int i = 0; i < table.thetaSamples(); ++i) {
      const std::span<const float> coeffs = table.slice(c, i).coefficients();
      if constexpr (std::endian::native == std::endian::little) {
        out.append(reinterpret_cast<const char*>(coeffs.data()), coeffs.size_bytes());
      } else {
        for (const float v : coeffs) appendLittleEndian<float>(out, v);
      }
    }
  }
  return out;
}

// The table in a payload for these options (which the header has matched).
// Throws std::runtime_error saying what is wrong with it.
BrdfSliceTable decodePayload(std::string_view payload, const SliceTableOptions& options) {
  if (options.level < 0 || options.level > kMaxLevel || options.thetaSamples < 1) {
    throw std::runtime_error("level " + std::to_string(options.level) + " or thetaSamples " +
                             std::to_string(options.thetaSamples) + " is out of range");
  }
  const std::size_t t = static_cast<std::size_t>(options.thetaSamples);
  const std::size_t count = coefficientsPerSlice(options.level);
  const std::size_t expected = 8 * t + 4 * BrdfSliceTable::kChannels * t * count;
  if (payload.size() != expected) {
    throw std::runtime_error("wrong size: a payload of " + std::to_string(payload.size()) + " bytes, expected " +
                             std::to_string(expected));
  }
  PayloadReader in(payload);
  std::vector<double> thetaOut(t);
  for (double& theta : thetaOut) theta = in.take<double>();
  std::vector<HaarMap> slices;
  slices.reserve(BrdfSliceTable::kChannels * t);
  for (std::size_t s = 0; s < BrdfSliceTable::kChannels * t; ++s) {
    HaarMap map(options.level);
    const std::span<float> coeffs = map.coefficients();
    if constexpr (std::endian::native == std::endian::little) {
      std::memcpy(coeffs.data(), in.takeBytes(count * sizeof(float)).data(), count * sizeof(float));
    } else {
      for (float& v : coeffs) v = in.take<float>();
    }
    slices.push_back(std::move(map));
  }
  try {
    return BrdfSliceTable::fromSlices(std::move(thetaOut), std::move(slices));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("invalid contents: ") + e.what());
  }
}

}  // namespace

std::string sliceCacheFileName(const std::string& key, const SliceTableOptions& options) {
  return cacheFileName(kKind, key, optionsText(options));
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
  return encodeCacheFile(header(options, key), encodePayload(table));
}

BrdfSliceTable decodeSliceTable(std::string_view bytes, const SliceTableOptions& options, const std::string& key) {
  std::string whyNot;
  const std::optional<std::string_view> payload = decodeCacheFile(bytes, header(options, key), &whyNot);
  if (!payload) throw std::runtime_error(whyNot);
  return decodePayload(*payload, options);
}

BrdfSliceTable loadOrBuildSliceTable(const Brdf& brdf, const SliceTableOptions& options, const std::string& cacheDir,
                                     const std::string& key, std::function<void(int, int)> progress,
                                     SliceCacheStatus* statusOut) {
  SliceCacheStatus local;
  SliceCacheStatus& status = statusOut ? *statusOut : local;
  status = SliceCacheStatus{};
  const bool warnOnStderr = statusOut == nullptr;

  // Options the builder refuses are its error to report, before any size is
  // computed from them.
  if (options.level < 0 || options.level > kMaxLevel || options.thetaSamples < 1 || options.supersampling < 1) {
    return BrdfSliceTable::build(brdf, options, progress);
  }

  // Look: any failure to read, any mismatch and any bad payload is a miss.
  const CacheHeader entry = header(options, key);
  if (const std::optional<std::string> payload = lookUpCacheEntry(cacheDir, entry, status)) {
    try {
      return decodePayload(*payload, options);
    } catch (const std::exception& e) {
      status.hit = false;
      status.reason = e.what();
      noteCacheRebuild(CacheRebuildReason::Corrupt, status.path, status.reason);
    }
  }

  BrdfSliceTable table = BrdfSliceTable::build(brdf, options, progress);
  if (key.size() > kMaxSliceCacheKey) {
    reportCacheError(status, warnOnStderr, kKind,
                     "key of " + std::to_string(key.size()) + " bytes is too long to cache");
    return table;
  }
  storeCacheEntry(cacheDir, entry, encodePayload(table), status, warnOnStderr);
  return table;
}

}  // namespace haarcast::io
