#include "loadtest_storage.h"

#include <chrono>
#include <stdexcept>
#include <string>

#include "haarcast/core/fused.h"
#include "haarcast/core/splitsum.h"

namespace haarcast::app {
namespace {

// The slice tables of every object at options.level, by the function
// prepareScene uses (same table options, same cache), without the visibility that
// prepareScene also computes: sizing level 6 then costs seconds, not the
// minutes level-6 visibility takes.
std::vector<BrdfSliceTable> sliceTables(const render::Scene& scene, const render::RenderOptions& options,
                                        const StageProgress& progress) {
  render::checkRenderOptions(options);
  std::vector<BrdfSliceTable> tables;
  for (const render::SceneObject& object : scene.objects) tables.push_back(render::objectSliceTable(object, options, progress));
  return tables;
}

}  // namespace

std::size_t methodStoredBytes(RotationMethod method, const std::vector<BrdfSliceTable>& tables,
                              const RotatorOptions& rotator) {
  std::size_t bytes = 0, shared = 0;  // every table has the same level: one shared part
  for (const BrdfSliceTable& table : tables) {
    if (method == RotationMethod::Splitsum) {
      // splitsum keeps its lobes alone (core/splitsum.h): 64 bytes per θₒ sample.
      bytes += splitsumStoredBytes(table.thetaSamples());
      continue;
    }
    if (method == RotationMethod::Fused) {
      // fused reads the unrotated slices in pixel form (cpu_backend.cpp keeps
      // exactly this per object), every channel, and the slices' detail
      // maps, which `serve` keeps at its default (the sum by cells).
      bytes += PixelSlices::synthesize(table, nullptr, true).storedBytes();
      continue;
    }
    // The CPU backend builds one rotator per channel (cpu_backend.cpp), so do
    // we; what they share (matrix: the elevation matrices) is stored once.
    for (int c = 0; c < BrdfSliceTable::kChannels; ++c) {
      const auto r = makeRotator(method, table.channelSlices(c), rotator);
      bytes += r->storedBytes() - r->sharedBytes();
      shared = std::max(shared, r->sharedBytes());
    }
  }
  return bytes + shared;
}

MethodStorage methodStorage(const render::Scene& scene, const render::RenderOptions& options,
                            const std::vector<RotationMethod>& methods, const StageProgress& progress) {
  MethodStorage out;
  out.level = options.level;
  const std::vector<BrdfSliceTable> tables = sliceTables(scene, options, progress);
  const std::string stage = "storage at level " + std::to_string(options.level);
  std::size_t done = 0;
  for (const RotationMethod method : methods) {
    if (progress) progress(stage, done, methods.size());
    const auto t0 = std::chrono::steady_clock::now();
    out.storedBytes[method] = methodStoredBytes(method, tables, options.rotator);
    out.precomputeSeconds[method] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (progress) progress(stage, ++done, methods.size());
  }
  return out;
}

SharedStorage sharedStorage(const render::PreparedScene& prepared) {
  SharedStorage s;
  for (const render::PreparedObject& o : prepared.objects) {
    for (const SparseHaar& v : o.visibility) s.visibilityBytes += v.size() * (sizeof(std::uint32_t) + sizeof(float));
    const Mesh& m = *o.mesh;
    s.meshBytes += m.positions.size() * sizeof(m.positions[0]) + m.normals.size() * sizeof(m.normals[0]) +
                   m.triangles.size() * sizeof(m.triangles[0]);
    s.sliceTableBytes += o.table.storedBytes() + o.pointTable.storedBytes();  // an empty point table has none
  }
  for (const SphereMap& channel : prepared.light) {
    s.level = channel.level();
    s.lightBytes += channel.values().size() * sizeof(float);
  }
  return s;
}

std::size_t prtDownloadBytes(std::size_t baselineStoredBytes, const SharedStorage& shared) {
  return baselineStoredBytes + shared.visibilityBytes + shared.lightBytes + shared.meshBytes;
}

double breakEvenSeconds(std::size_t downloadBytes, double bitsPerSecond) {
  if (!(bitsPerSecond > 0.0)) {
    throw std::invalid_argument("break-even: the stream's rate must be positive (got " + std::to_string(bitsPerSecond) +
                                " bit/s)");
  }
  return static_cast<double>(downloadBytes) * 8.0 / bitsPerSecond;
}

}  // namespace haarcast::app
