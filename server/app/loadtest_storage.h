// What `haarcast loadtest` says about storage: the coefficient bytes each
// per-pixel method holds for one scene at one level, and the bytes a client
// would have to download to render that scene itself from precomputed
// radiance-transfer data (the PRT baseline: Ng et al. 2004's pre-rotated
// table, Wang et al. 2006's rotation matrices).
//
// Every figure comes from the code that holds the data, never from a copied
// formula: the slice tables from prepareScene / the slice cache, the method's
// data from makeRotator(...)->storedBytes() (rotation.h: the unrotated slices
// plus whatever the method precomputed, or for `table` the copies that replace
// them) and, for `fused`, PixelSlices::storedBytes() (the slices in pixel form,
// the only BRDF data fused reads); for `splitsum`, splitsumStoredBytes (its
// lobes, one per θₒ sample: it keeps no slices). Visibility, light and meshes are the same
// for every method and counted apart.
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "haarcast/core/rotation.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/scene.h"
#include "progress.h"

namespace haarcast::app {

// The BRDF coefficient bytes each method holds for the scene at one level,
// summed over objects and colour channels. Needs only the slice tables (no
// visibility), so that level 6 is cheap to size even when the runs render
// at a lower level.
struct MethodStorage {
  int level = 0;
  std::map<RotationMethod, std::size_t> storedBytes;
  std::map<RotationMethod, double> precomputeSeconds;  // building the method's data here
};

// The data every method shares at the runs' level, from prepareScene.
struct SharedStorage {
  int level = 0;
  std::size_t visibilityBytes = 0;  // per-vertex lists: (index, value) per kept coefficient
  std::size_t lightBytes = 0;       // the environment at the level, 3 channels of M² floats
  std::size_t meshBytes = 0;        // positions, normals, triangles
  std::size_t sliceTableBytes = 0;  // the unrotated slices (BrdfSliceTable::storedBytes)
};

// options: the renderer options the server uses (level, θₒ samples, slice
// supersampling, rotator options, cache folder). Throws what prepareScene
// and makeRotator throw.
MethodStorage methodStorage(const render::Scene& scene, const render::RenderOptions& options,
                            const std::vector<RotationMethod>& methods, const StageProgress& progress = {});
SharedStorage sharedStorage(const render::PreparedScene& prepared);

// Bytes one method's data takes for one set of slice tables (one per
// object): the definition methodStorage uses.
std::size_t methodStoredBytes(RotationMethod method, const std::vector<BrdfSliceTable>& tables,
                              const RotatorOptions& rotator);

// The PRT download baseline: what a client must hold to render the scene
// itself with `baseline`'s data (table or matrix): that method's BRDF data,
// visibility, light and meshes.
std::size_t prtDownloadBytes(std::size_t baselineStoredBytes, const SharedStorage& shared);

// Seconds of streaming at bitsPerSecond after which the stream has carried
// as many bytes as the download: bytes·8 / bitsPerSecond. Throws
// std::invalid_argument unless bitsPerSecond > 0.
double breakEvenSeconds(std::size_t downloadBytes, double bitsPerSecond);

}  // namespace haarcast::app
