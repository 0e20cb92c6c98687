// The visibility cache: a "visibility" cache file (io/cache_file.h) whose
// payload is the per-vertex sparse Haar coefficients (layout in
// visibility_cache.h).
#include "haarcast/render/visibility_cache.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <system_error>

#include "haarcast/io/cache_rebuilds.h"

namespace haarcast {
namespace {

constexpr const char* kKind = "visibility";

// FNV-1a 64 over a stream of little-endian numbers, hashed in chunks so a
// large mesh is never copied whole.
class ContentHasher {
 public:
  template <typename T>
  void add(T value) {
    io::appendLittleEndian(buffer_, value);
    if (buffer_.size() >= kChunk) flush();
  }
  std::uint64_t finish() {
    flush();
    return hash_;
  }

 private:
  static constexpr std::size_t kChunk = 1 << 16;
  void flush() {
    hash_ = io::fnv1a64(buffer_, hash_);
    buffer_.clear();
  }
  std::string buffer_;
  std::uint64_t hash_ = io::kFnv1a64Basis;
};

// The shortest decimal that reads back as the same number: exact, and
// readable in a hex dump.
template <typename T>
std::string shortestDecimal(T value) {
  char text[32];
  const std::to_chars_result r = std::to_chars(text, text + sizeof text, value);
  return r.ec == std::errc() ? std::string(text, r.ptr) : std::string("?");
}

// The cache's one path for both kinds: bad input first (the same error hit
// or miss), then a valid file's payload decoded, else computed and stored.
// A payload that does not decode is counted and logged as a rebuild.
template <typename Decode, typename Compute, typename Encode>
auto loadOrCompute(const Mesh& mesh, const VisibilityOptions& options, const std::string& cacheDir,
                   const io::CacheHeader& entry, VisibilityCacheStatus* statusOut, Decode&& decode, Compute&& compute,
                   Encode&& encode) -> decltype(compute()) {
  VisibilityCacheStatus local;
  VisibilityCacheStatus& status = statusOut ? *statusOut : local;
  status = VisibilityCacheStatus{};
  const bool warnOnStderr = statusOut == nullptr;
  checkVisibilityOptions(options);
  mesh.validate();
  if (cacheDir.empty()) {
    status.reason = "no cache directory";
    return compute();
  }
  if (const std::optional<std::string> payload = io::lookUpCacheEntry(cacheDir, entry, status)) {
    try {
      return decode(*payload);
    } catch (const std::exception& e) {
      status.hit = false;
      status.reason = e.what();
      io::noteCacheRebuild(io::CacheRebuildReason::Corrupt, status.path, status.reason);
    }
  }
  auto computed = compute();
  std::string payload;
  try {
    payload = encode(computed);
  } catch (const std::exception& e) {
    io::reportCacheError(status, warnOnStderr, entry.kind, e.what());
    return computed;
  }
  io::storeCacheEntry(cacheDir, entry, payload, status, warnOnStderr);
  return computed;
}

}  // namespace

std::string meshContentKey(const Mesh& mesh) {
  ContentHasher h;
  // Each array's length goes first, so bytes cannot move from one to the next
  // and leave the hash unchanged.
  h.add<std::uint64_t>(mesh.positions.size());
  for (const glm::vec3& p : mesh.positions) {
    h.add(p.x);
    h.add(p.y);
    h.add(p.z);
  }
  h.add<std::uint64_t>(mesh.normals.size());
  for (const glm::vec3& n : mesh.normals) {
    h.add(n.x);
    h.add(n.y);
    h.add(n.z);
  }
  h.add<std::uint64_t>(mesh.triangles.size());
  for (const glm::uvec3& t : mesh.triangles) {
    h.add<std::uint32_t>(t.x);
    h.add<std::uint32_t>(t.y);
    h.add<std::uint32_t>(t.z);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h.finish()));
  return std::string("mesh-fnv1a64:") + hex + " vertices=" + std::to_string(mesh.positions.size()) +
         " triangles=" + std::to_string(mesh.triangles.size());
}

std::string visibilityOptionsText(const VisibilityOptions& options) {
  return "level=" + std::to_string(options.level) + " supersampling=" + std::to_string(options.supersampling) +
         " keep=" + std::to_string(options.keep) + " offset=" + shortestDecimal(options.offset);
}

std::string encodeVisibilityPayload(const std::vector<SparseHaar>& visibility) {
  std::size_t bytes = 8;
  for (const SparseHaar& v : visibility) bytes += 4 + 8 * v.size();
  std::string out;
  out.reserve(bytes);
  io::appendLittleEndian<std::uint64_t>(out, visibility.size());
  for (const SparseHaar& v : visibility) {
    if (v.value.size() != v.index.size()) {
      throw std::invalid_argument("encodeVisibilityPayload: " + std::to_string(v.index.size()) + " indices but " +
                                  std::to_string(v.value.size()) + " values");
    }
    io::appendLittleEndian<std::uint32_t>(out, static_cast<std::uint32_t>(v.size()));
    for (std::size_t k = 0; k < v.size(); ++k) {
      io::appendLittleEndian<std::uint32_t>(out, v.index[k]);
      io::appendLittleEndian<float>(out, v.value[k]);
    }
  }
  return out;
}

std::vector<SparseHaar> decodeVisibilityPayload(std::string_view payload, std::size_t vertexCount,
                                                const VisibilityOptions& options) {
  checkVisibilityOptions(options);
  const std::uint64_t coefficients = static_cast<std::uint64_t>(mapSize(options.level)) *
                                     static_cast<std::uint64_t>(mapSize(options.level));
  const std::uint64_t maxPerVertex = std::min<std::uint64_t>(options.keep, coefficients);
  io::PayloadReader in(payload);
  const auto count = in.take<std::uint64_t>();
  if (count != vertexCount) {
    throw std::runtime_error("invalid contents: " + std::to_string(count) + " vertices, the mesh has " +
                             std::to_string(vertexCount));
  }
  std::vector<SparseHaar> visibility(vertexCount);
  for (std::size_t vertex = 0; vertex < vertexCount; ++vertex) {
    const std::string where = "invalid contents: vertex " + std::to_string(vertex) + ": ";
    const auto n = in.take<std::uint32_t>();
    if (n > maxPerVertex) {
      throw std::runtime_error(where + std::to_string(n) + " coefficients, at most " + std::to_string(maxPerVertex));
    }
    // Known to fit in what is left before anything is allocated for it.
    if (8ull * n > in.remaining()) {
      throw std::runtime_error(where + std::to_string(n) + " coefficients but only " +
                               std::to_string(in.remaining()) + " bytes left");
    }
    SparseHaar& v = visibility[vertex];
    v.level = options.level;
    v.index.resize(n);
    v.value.resize(n);
    for (std::uint32_t k = 0; k < n; ++k) {
      const auto index = in.take<std::uint32_t>();
      const auto value = in.take<float>();
      if (index >= coefficients) {
        throw std::runtime_error(where + "index " + std::to_string(index) + " is past the " +
                                 std::to_string(coefficients) + " coefficients of a level-" +
                                 std::to_string(options.level) + " map");
      }
      if (k > 0 && index <= v.index[k - 1]) throw std::runtime_error(where + "indices are not increasing");
      if (!std::isfinite(value)) throw std::runtime_error(where + "a non-finite coefficient");
      v.index[k] = index;
      v.value[k] = value;
    }
  }
  if (in.remaining() != 0) {
    throw std::runtime_error("invalid contents: " + std::to_string(in.remaining()) + " bytes after the last vertex");
  }
  return visibility;
}

std::vector<SparseHaar> loadOrComputeVertexVisibility(
    const Mesh& mesh, const VisibilityOptions& options, const std::string& cacheDir,
    const std::function<void(std::size_t done, std::size_t total)>& progress, VisibilityCacheStatus* statusOut) {
  const io::CacheHeader entry{kKind, kVisibilityCacheVersion, cacheDir.empty() ? std::string() : meshContentKey(mesh),
                              visibilityOptionsText(options)};
  return loadOrCompute(
      mesh, options, cacheDir, entry, statusOut,
      [&](std::string_view payload) { return decodeVisibilityPayload(payload, mesh.positions.size(), options); },
      [&] { return computeVertexVisibility(mesh, options, progress); },
      [](const std::vector<SparseHaar>& v) { return encodeVisibilityPayload(v); });
}

namespace {

std::string bitsOptionsText(const VisibilityOptions& options) {
  return "level=" + std::to_string(options.level) + " offset=" + shortestDecimal(options.offset) +
         " skip=" + shortestDecimal(kBitsSkipBelowDegrees);
}

VisibilityBits decodeBits(std::string_view payload, std::size_t vertexCount, int level) {
  io::PayloadReader in(payload);
  const auto count = in.take<std::uint64_t>();
  if (count != vertexCount) {
    throw std::runtime_error("invalid contents: " + std::to_string(count) + " vertices, the mesh has " +
                             std::to_string(vertexCount));
  }
  VisibilityBits bits(level, vertexCount);
  const std::size_t words = vertexCount * bits.wordsPerPoint();
  if (in.remaining() != 4 * words) {
    throw std::runtime_error("invalid contents: " + std::to_string(in.remaining()) + " bytes of words, expected " +
                             std::to_string(4 * words));
  }
  std::vector<std::uint32_t> w(words);
  for (std::uint32_t& x : w) x = in.take<std::uint32_t>();
  try {
    bits.assign(w);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("invalid contents: ") + e.what());
  }
  return bits;
}

}  // namespace

VisibilityBits loadOrComputeVisibilityBits(const Mesh& mesh, const VisibilityOptions& options, const std::string& cacheDir,
                                           const std::function<void(std::size_t done, std::size_t total)>& progress,
                                           VisibilityCacheStatus* statusOut) {
  const io::CacheHeader entry{"visibility-bits", kVisibilityBitsCacheVersion,
                              cacheDir.empty() ? std::string() : meshContentKey(mesh), bitsOptionsText(options)};
  return loadOrCompute(
      mesh, options, cacheDir, entry, statusOut,
      [&](std::string_view payload) { return decodeBits(payload, mesh.positions.size(), options.level); },
      [&] { return computeVisibilityBits(mesh, options, progress); },
      [](const VisibilityBits& bits) {
        std::string payload;
        payload.reserve(8 + bits.storedBytes());
        io::appendLittleEndian<std::uint64_t>(payload, bits.pointCount());
        for (const std::uint32_t w : bits.words()) io::appendLittleEndian<std::uint32_t>(payload, w);
        return payload;
      });
}

namespace {

std::string refinedOptionsText(const VisibilityOptions& options, const RefineOptions& r) {
  return bitsOptionsText(options) + " rounds=" + std::to_string(r.rounds) + " threshold=" + shortestDecimal(r.threshold) +
         " min-edge=" + shortestDecimal(r.minEdge) + " growth=" + shortestDecimal(r.growth) +
         " floor=" + std::to_string(r.floor);
}

std::string encodeRefined(const RefinedVisibility& r) {
  std::string out;
  out.reserve(24 + 24 * r.mesh.positions.size() + 12 * r.mesh.triangles.size() + r.bits.storedBytes());
  io::appendLittleEndian<std::uint64_t>(out, r.mesh.positions.size());
  io::appendLittleEndian<std::uint64_t>(out, r.mesh.triangles.size());
  io::appendLittleEndian<std::uint32_t>(out, static_cast<std::uint32_t>(r.rounds));
  for (std::size_t v = 0; v < r.mesh.positions.size(); ++v)
    for (const glm::vec3& x : {r.mesh.positions[v], r.mesh.normals[v]})
      for (int c = 0; c < 3; ++c) io::appendLittleEndian<float>(out, x[c]);
  for (const glm::uvec3& t : r.mesh.triangles)
    for (int c = 0; c < 3; ++c) io::appendLittleEndian<std::uint32_t>(out, t[c]);
  for (const std::uint32_t w : r.bits.words()) io::appendLittleEndian<std::uint32_t>(out, w);
  return out;
}

// The refined mesh must start with the original's vertices unchanged (the
// refinement only adds), have valid triangles and bits of the right size.
RefinedVisibility decodeRefined(std::string_view payload, const Mesh& original, const VisibilityOptions& options,
                                const RefineOptions& refine) {
  io::PayloadReader in(payload);
  const auto vertices = in.take<std::uint64_t>();
  const auto triangles = in.take<std::uint64_t>();
  const auto rounds = in.take<std::uint32_t>();
  const std::size_t words = visibilityWordsPerPoint(options.level);
  if (vertices < original.positions.size() || rounds > static_cast<std::uint32_t>(refine.rounds) ||
      in.remaining() != vertices * (24 + 4 * words) + 12 * triangles) {
    throw std::runtime_error("invalid contents: " + std::to_string(vertices) + " vertices, " +
                             std::to_string(triangles) + " triangles and " + std::to_string(in.remaining()) +
                             " bytes do not fit the mesh's " + std::to_string(original.positions.size()) + " vertices");
  }
  RefinedVisibility r;
  r.rounds = static_cast<int>(rounds);
  r.mesh.name = original.name;
  r.mesh.positions.resize(vertices);
  r.mesh.normals.resize(vertices);
  for (std::size_t v = 0; v < vertices; ++v) {
    for (glm::vec3* x : {&r.mesh.positions[v], &r.mesh.normals[v]})
      for (int c = 0; c < 3; ++c) (*x)[c] = in.take<float>();
    if (v < original.positions.size() &&
        (r.mesh.positions[v] != original.positions[v] || r.mesh.normals[v] != original.normals[v])) {
      throw std::runtime_error("invalid contents: vertex " + std::to_string(v) + " differs from the mesh's");
    }
  }
  r.mesh.triangles.resize(triangles);
  for (glm::uvec3& t : r.mesh.triangles)
    for (int c = 0; c < 3; ++c) t[c] = in.take<std::uint32_t>();
  try {
    r.mesh.validate();
    r.bits = VisibilityBits(options.level, vertices);
    std::vector<std::uint32_t> w(vertices * words);
    for (std::uint32_t& x : w) x = in.take<std::uint32_t>();
    r.bits.assign(w);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("invalid contents: ") + e.what());
  }
  return r;
}

}  // namespace

RefinedVisibility loadOrComputeRefinedVisibility(const Mesh& mesh, const VisibilityOptions& options,
                                                 const RefineOptions& refine, const std::string& cacheDir,
                                                 const std::function<void(std::size_t done, std::size_t total)>& progress,
                                                 VisibilityCacheStatus* statusOut) {
  checkRefineOptions(refine);
  const io::CacheHeader entry{"visibility-refined", kRefinedVisibilityCacheVersion,
                              cacheDir.empty() ? std::string() : meshContentKey(mesh), refinedOptionsText(options, refine)};
  return loadOrCompute(
      mesh, options, cacheDir, entry, statusOut,
      [&](std::string_view payload) { return decodeRefined(payload, mesh, options, refine); },
      [&] { return computeRefinedVisibility(mesh, options, refine, progress); }, encodeRefined);
}

}  // namespace haarcast
