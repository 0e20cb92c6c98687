// The on-disk cache of per-vertex visibility. Ray-casting s²·M² directions per
// vertex is the slowest part of preparing an object (the bunny at level 5:
// seconds); the coefficients read back from disk are bit-identical.
//
// Files are haarcast cache files (io/cache_file.h) of kind "visibility",
// version kVisibilityCacheVersion.
// - Key: meshContentKey(mesh), a hash of the mesh's contents, not of a path:
//   scenes centre, scale and otherwise change meshes in memory after loading,
//   and what the rays see is the mesh as given.
// - Options text: "level=<n> supersampling=<s> keep=<k> offset=<shortest
//   round-trip decimal of the float>", so any change of option is a miss.
// - Payload, little-endian:
//     u64  vertex count V
//     then per vertex: u32 count n; n × (u32 index, f32 value), indices
//     strictly increasing, as SparseHaar holds them.
// Decoding checks everything a damaged file could get wrong even when its
// checksum matches — V against the mesh, n ≤ min(keep, M²), every index < M²
// and increasing, every value finite, no bytes left over — and any failure is
// a miss: the visibility is recomputed and the file rewritten.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "haarcast/core/haar.h"
#include "haarcast/core/mesh.h"
#include "haarcast/io/cache_file.h"
#include "haarcast/render/visibility.h"
#include "haarcast/render/visibility_refine.h"

namespace haarcast {

// Bump whenever the payload layout or what computeVertexVisibility computes
// (sampling, offset rule, truncation) changes: old files then miss.
inline constexpr std::uint32_t kVisibilityCacheVersion = 1;

using VisibilityCacheStatus = io::CacheStatus;

// computeVertexVisibility(mesh, options, progress), read from `cacheDir` when
// a valid file for (mesh contents, options) is there, else computed and then
// written there for next time (the directory is created if missing). On a hit
// progress is never called. An empty cacheDir means no cache: the visibility
// is computed and status->reason says so.
// The cache never makes this fail: when the directory or the file cannot be
// read or written the visibility is computed all the same, and the failure
// goes to status->error, or to one line on stderr when no status is asked
// for. Bad options or an invalid mesh throw std::invalid_argument, hit or
// miss, as computeVertexVisibility does.
std::vector<SparseHaar> loadOrComputeVertexVisibility(
    const Mesh& mesh, const VisibilityOptions& options, const std::string& cacheDir,
    const std::function<void(std::size_t done, std::size_t total)>& progress = {},
    VisibilityCacheStatus* status = nullptr);

// `fused`'s visibility bits (computeVisibilityBits) through the same cache,
// files of kind "visibility-bits", version kVisibilityBitsCacheVersion:
// options text "level=<n> offset=<float> skip=<degrees>", payload u64 V then
// V·W u32 words (W = visibilityWordsPerPoint(level)), little-endian. A
// payload of the wrong size, or with a bit set past the map's directions,
// is a miss.
inline constexpr std::uint32_t kVisibilityBitsCacheVersion = 1;
VisibilityBits loadOrComputeVisibilityBits(const Mesh& mesh, const VisibilityOptions& options, const std::string& cacheDir,
                                           const std::function<void(std::size_t done, std::size_t total)>& progress = {},
                                           VisibilityCacheStatus* status = nullptr);

// `fused`'s refined mesh and its bits (computeRefinedVisibility), files of
// kind "visibility-refined" keyed by the original mesh: options text the
// bits' plus "rounds=… threshold=… min-edge=… growth=… floor=…"; payload
// u64 V, u64 T, u32 rounds, V × (position, normal: 6 f32), T × 3 u32, V·W
// u32 words. A refined mesh whose first vertices are not the original's, a
// triangle out of range or a payload of the wrong size is a miss.
inline constexpr std::uint32_t kRefinedVisibilityCacheVersion = 1;
RefinedVisibility loadOrComputeRefinedVisibility(const Mesh& mesh, const VisibilityOptions& options,
                                                 const RefineOptions& refine, const std::string& cacheDir,
                                                 const std::function<void(std::size_t done, std::size_t total)>& progress = {},
                                                 VisibilityCacheStatus* status = nullptr);

// "mesh-fnv1a64:<16 hex digits> vertices=<V> triangles=<T>": FNV-1a 64 over
// the counts and the little-endian bytes of positions, normals and triangles
// (names are left out: they do not change what the rays see). A moved vertex,
// a changed normal or a re-wound triangle changes it; two different meshes
// share it only by a 64-bit hash collision.
std::string meshContentKey(const Mesh& mesh);

// The canonical options text stored in the file (see above).
std::string visibilityOptionsText(const VisibilityOptions& options);

// The payload for `visibility` (one SparseHaar per vertex, as computed), and
// back. decodeVisibilityPayload throws std::runtime_error saying what is
// wrong when the payload is not valid for `vertexCount` vertices under
// `options` (see above); it never reads outside `payload`.
std::string encodeVisibilityPayload(const std::vector<SparseHaar>& visibility);
std::vector<SparseHaar> decodeVisibilityPayload(std::string_view payload, std::size_t vertexCount,
                                                const VisibilityOptions& options);

}  // namespace haarcast
