// The scene data a VulkanRenderer uploads once (slices, method data, meshes,
// visibility, backdrop), the compute pipelines that read it and, for
// `fused`, the ray scene of the point lights' shadow rays.

#include <cmath>
#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "haarcast/core/fused.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/shared_smooth.h"
#include "haarcast/gpu/rotation_data.h"

#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

void VulkanRenderer::Impl::uploadScene() {
  const std::size_t objectCount = prepared.objects.size();
  const auto T = static_cast<std::size_t>(options.thetaSamples);
  const std::size_t n = coefficients;

  // Slices: global slice s = object's base + t, channel c at (s·3 + c)·N
  // (the rotation contract's kRotateSlicesBinding).
  std::vector<float> sliceData;
  std::vector<float> pointData;  // fused: the slices as point values, laid out as sliceData
  std::vector<float> detailData;  // fused: global slice s's detail map at s·kCellDetailStride (shared_cells.h)
  std::vector<std::uint32_t> method;
  std::vector<glm::vec4> pos, nor;
  std::vector<std::uint32_t> tri;
  std::vector<SparseHaar> vis;
  std::vector<std::uint32_t> bits;  // fused: every vertex's visibility words, global vertex order
  std::vector<glm::vec4> energies;           // fused: per global slice, ∫ρ_c (rgb)
  std::vector<shared::SliceLobe> lobeData;   // fused: per global slice, its lobe (zero: none)
  objectInfo.resize(objectCount);
  // fused: each object at its own level (PreparedObject::level), its data
  // at its own bases (ObjectInfo), the directions of every level in use in
  // one table: the objects' and their lights' turn levels (fused_light.cpp).
  std::vector<int> directionLevels = prepared.objectLevels();
  for (const render::PreparedObject& p : prepared.objects) directionLevels.push_back(render::lightTurnLevel(p.level));
  const DirectionTable directionTable = fused ? pixelCentreDirections(directionLevels) : DirectionTable{};
  fusedLightTexelCount = 0;
  for (std::size_t k = 0; k < objectCount; ++k) {
    const render::PreparedObject& p = prepared.objects[k];
    ObjectInfo& info = objectInfo[k];
    const int objectLevel = fused ? p.level : level;
    if (splitsum ? p.lobes.size() != T
                 : static_cast<std::size_t>(p.table.thetaSamples()) != T || p.table.level() != objectLevel) {
      throw std::logic_error("Vulkan backend: object " + p.name + " has a slice table unlike the options");
    }
    info.thetaSamples = static_cast<std::uint32_t>(T);
    info.flags = p.ground ? shared::kObjectGround : 0u;
    if (objectSky() && !p.ground) info.flags |= shared::kObjectSkyHidden;
    if (splitsum) {
      // Its lobes are all it keeps: lobe t of the object at sliceBase + t.
      info.sliceBase = static_cast<std::uint32_t>(lobeData.size());
      lobeData.insert(lobeData.end(), p.lobes.begin(), p.lobes.end());
    } else if (fused) {
      // The slices in pixel form, RGB0 texels (core PixelSlices), the
      // object's slice t at texelBase + t·N of its level; its energies and
      // lobes at global slice sliceBase + t; its light at lightBase.
      const PixelSlices pixelSlices = PixelSlices::synthesize(p.table, p.finerPointTable(), p.sumTolerance > 0.0f);
      const std::size_t objectN = static_cast<std::size_t>(mapSize(p.level)) * static_cast<std::size_t>(mapSize(p.level));
      info.level = static_cast<std::uint32_t>(p.level);
      info.sliceBase = static_cast<std::uint32_t>(energies.size());
      info.texelBase = static_cast<std::uint32_t>(sliceData.size() / shared::kTexelFloats);
      info.pointLevel = static_cast<std::uint32_t>(pixelSlices.pointLevel());
      info.pointTexelBase = static_cast<std::uint32_t>(pointData.size() / shared::kTexelFloats);
      info.lightBase = static_cast<std::uint32_t>(fusedLightTexelCount);
      info.directionBase = directionTable.base[static_cast<std::size_t>(p.level)];
      fusedLightTexelCount += objectN;
      // By cells (PreparedObject::sumTolerance, as the CPU): the light's
      // cells after its texels, the slices' detail maps.
      if (p.sumTolerance > 0.0f) {
        info.sumTolerance = p.sumTolerance;
        fusedLightTexelCount += 2 * objectN / shared::kCellDirections;
      }
      detailData.resize((static_cast<std::size_t>(info.sliceBase) + T) * shared::kCellDetailStride, 0.0f);
      for (std::size_t t = 0; t < T && pixelSlices.detail(0); ++t) {
        const float* d = pixelSlices.detail(static_cast<int>(t));
        std::copy(d, d + objectN / shared::kCellDirections, detailData.begin() + static_cast<std::ptrdiff_t>((info.sliceBase + t) * shared::kCellDetailStride));
      }
      sliceData.insert(sliceData.end(), pixelSlices.texels().begin(), pixelSlices.texels().end());
      pointData.insert(pointData.end(), pixelSlices.pointTexels().begin(), pixelSlices.pointTexels().end());
      setFusedSkip(info, p.level, pixelSlices.lastNonZeroRow());
      for (std::size_t t = 0; t < T; ++t) {
        const std::array<float, 3>& e = pixelSlices.energy(static_cast<int>(t));
        energies.emplace_back(e[0], e[1], e[2], 0.0f);
        lobeData.push_back(p.lobes.empty() ? shared::SliceLobe{} : p.lobes[t]);
      }
      if (p.lobePath) {
        info.flags |= shared::kObjectLobePath;
        info.lobeCore.x = std::cos(p.lobeCore);  // fused.cpp setCore's cos, in float
      }
      info.lobeCore.y = shared::smoothMirrorCos(p.sharpestLobe);  // as cpu_backend.cpp's shadeSmoothSums
    } else {
      info.sliceBase = static_cast<std::uint32_t>(sliceData.size() / (3 * n));
      for (std::size_t t = 0; t < T; ++t) {
        for (int c = 0; c < 3; ++c) {
          const auto coeffs = p.table.slice(c, static_cast<int>(t)).coefficients();
          sliceData.insert(sliceData.end(), coeffs.begin(), coeffs.end());
        }
      }
    }
    const std::size_t before = method.size();
    info.methodBase = options.method == RotationMethod::Spatial || fused || splitsum
                          ? static_cast<std::uint32_t>(method.size())
                          : appendRotationData(options.method, p.table, info.sliceBase, method, options.rotator);
    const std::size_t blockWords = method.size() - before;
    // Bytes of method data one rotation of one channel reads: haar reads its
    // map's differences ((2M−1)·M words); table reads one copy instead of the
    // slice; matrix reads two of its K elevation matrices.
    std::size_t methodBytes = 0;
    const std::size_t m = static_cast<std::size_t>(mapSize(level));
    switch (options.method) {
      case RotationMethod::Haar: methodBytes = (2 * m - 1) * m * 4; break;
      case RotationMethod::Table: methodBytes = 0; break;
      case RotationMethod::Matrix: {
        const std::size_t matrices = std::max<std::size_t>(1, method.size() > before ? method[before] : 1);
        methodBytes = 2 * (blockWords * 4) / matrices;
        break;
      }
      case RotationMethod::Spatial:
      case RotationMethod::Fused:
      case RotationMethod::Splitsum: break;
    }
    methodBytesPerChannel.push_back(methodBytes);

    info.vertexBase = static_cast<std::uint32_t>(pos.size());
    info.triangleBase = static_cast<std::uint32_t>(tri.size() / 3);
    const Mesh& mesh = *p.mesh;
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
      pos.emplace_back(mesh.positions[v], 1.0f);
      nor.emplace_back(mesh.normals[v], 0.0f);
    }
    for (const glm::uvec3& t : mesh.triangles) {
      tri.push_back(info.vertexBase + t.x);
      tri.push_back(info.vertexBase + t.y);
      tri.push_back(info.vertexBase + t.z);
    }
    triangleCount.push_back(static_cast<std::uint32_t>(mesh.triangles.size()));
    if (splitsum) continue;  // its visibility is the host's one ray per sample
    if (fused) {
      // fused reads the bits (core VisibilityBits), never the lists.
      const VisibilityBits& b = p.visibilityBits;
      if (b.pointCount() != mesh.positions.size() || b.level() != p.level ||
          b.wordsPerPoint() != shared::visibilityWords(static_cast<shared::uint>(p.level))) {
        throw std::logic_error("Vulkan backend: object " + p.name + " has visibility bits for " +
                               std::to_string(b.pointCount()) + " points at level " + std::to_string(b.level()) +
                               " for " + std::to_string(mesh.positions.size()) + " vertices at level " +
                               std::to_string(p.level));
      }
      info.visibilityBase = static_cast<std::uint32_t>(bits.size());
      bits.insert(bits.end(), b.words().begin(), b.words().end());
      continue;
    }
    if (p.visibility.size() != mesh.positions.size()) {
      throw std::logic_error("Vulkan backend: object " + p.name + " has " + std::to_string(p.visibility.size()) +
                             " visibility maps for " + std::to_string(mesh.positions.size()) + " vertices");
    }
    vis.insert(vis.end(), p.visibility.begin(), p.visibility.end());
  }
  vertexCount = pos.size();
  totalTriangles = tri.size() / 3;
  rotationBytesPerChannel = n * sizeof(float);  // the slice, or for table the copy that replaces it

  // Read-only inputs in device-local memory (buffer.h): written straight
  // into their mapping, or staged and copied in one command buffer below.
  std::vector<BufferUpload> uploads;
  // `fused` reads its large inputs as texel buffers (fused.comp), so they
  // carry that usage too.
  const VkBufferUsageFlags fusedUsage = fused ? kTexelUsage : kStorageUsage;
  auto input = [&](Buffer& b, std::size_t bytes, VkBufferUsageFlags usage = kStorageUsage) -> BufferUpload& {
    b = Buffer(context, bytes, usage, MemoryUse::DeviceInput);
    return uploads.emplace_back(context, b);
  };
  auto upload = [&](Buffer& b, const void* data, std::size_t bytes, VkBufferUsageFlags usage = kStorageUsage) {
    input(b, bytes, usage).write(data, bytes);
  };
  if (splitsum) {
    upload(lobes, lobeData.data(), lobeData.size() * sizeof(shared::SliceLobe));
    upload(lobeLight, prepared.lobeLight.texels().data(), prepared.lobeLight.texels().size_bytes(), kTexelUsage);
  } else if (fused) {
    // The bits as they are (W words per vertex, vertex v of object o at
    // global vertex o's vertexBase + v): fused.comp blends three vertices'
    // bits per direction.
    upload(visibility, bits.data(), bits.size() * sizeof(std::uint32_t), kTexelUsage);
  } else {
    const std::vector<glm::uvec4> visPacked = packSparseLists(vis, level);
    visibilityBlocks.resize(vis.size());
    for (std::size_t v = 0; v < vis.size(); ++v) visibilityBlocks[v] = visPacked[v].y;
    upload(visibility, visPacked.data(), visPacked.size() * sizeof(glm::uvec4));
  }
  if (!splitsum) upload(slices, sliceData.data(), sliceData.size() * sizeof(float), fusedUsage);
  if (method.empty()) method.push_back(0u);  // spatial: a 4-byte dummy (the contract)
  upload(methodData, method.data(), method.size() * sizeof(std::uint32_t));
  upload(positions, pos.data(), pos.size() * sizeof(glm::vec4));
  upload(normals, nor.data(), nor.size() * sizeof(glm::vec4));
  upload(triangles, tri.data(), tri.size() * sizeof(std::uint32_t));

  // Backdrop maps, [channel][row][col].
  std::vector<float> bg;
  for (const SphereMap& map : prepared.background) bg.insert(bg.end(), map.values().begin(), map.values().end());
  upload(background, bg.data(), bg.size() * sizeof(float));
  if (fused) {
    // The pixel-centre directions of every level in use, as core fused
    // builds them (double → float).
    upload(directions, directionTable.directions.data(), directionTable.directions.size() * sizeof(glm::vec4), kTexelUsage);
    upload(sliceEnergy, energies.data(), energies.size() * sizeof(glm::vec4));
    upload(pointSlices, pointData.data(), pointData.size() * sizeof(float), kTexelUsage);
    if (detailData.empty()) detailData.push_back(0.0f);  // a buffer may not be empty
    upload(details, detailData.data(), detailData.size() * sizeof(float), kTexelUsage);
    upload(lobes, lobeData.data(), lobeData.size() * sizeof(shared::SliceLobe));
    // No object with a lobe path: one zero texel, never read (a buffer may not be empty).
    const glm::vec4 none(0.0f);
    const std::span<const glm::vec4> prefiltered =
        prepared.lobeLight.empty() ? std::span<const glm::vec4>(&none, 1) : prepared.lobeLight.texels();
    upload(lobeLight, prefiltered.data(), prefiltered.size_bytes(), kTexelUsage);
  }
  submitUploads(context, uploads);

  objects = Buffer(context, objectCount * sizeof(ObjectInfo));
  if (splitsum) {
    // No light per frame: the pass turns its lookup (ObjectInfo::toLight).
    // The mirror rays' scene, as fused's shadow rays' (below), where the host traces them.
    if (!deviceRays) createHostRays();
  }
  // The light: per object and channel a header and at most (N − 1)/3 blocks,
  // written by the host every frame, device-local like the other inputs: its
  // upload (and staging buffer, where there is one) lives as long as the
  // renderer. `fused`'s is its pixel form, N RGB0 texels per object at its
  // level (then its cells), which the device makes (fused_light.cpp).
  if (fused) {
    light = Buffer(context, fusedLightTexelCount * sizeof(glm::vec4), kTexelUsage, MemoryUse::DeviceOnly);
  } else if (!splitsum) {
    light = Buffer(context, objectCount * 3 * (1 + (n - 1) / 3) * sizeof(glm::uvec4), kStorageUsage, MemoryUse::DeviceInput);
    lightUpload = BufferUpload(context, light);
  }
  if (fused) {
    // The point lights, written every frame like the light.
    pointLightData.assign(objectCount * shared::kMaxPointLights, PointLight{});
    pointLights = Buffer(context, pointLightData.size() * sizeof(PointLight), kStorageUsage, MemoryUse::DeviceInput);
    pointLightUpload = BufferUpload(context, pointLights);
    // Per object, its samples shaded from one slice and from two (fused.comp).
    sliceCounts = Buffer(context, shared::kSliceCountsPerObject * objectCount * sizeof(std::uint32_t), kStorageUsage,
                         MemoryUse::DeviceOnly);
    sliceCountsOut = Buffer(context, shared::kSliceCountsPerObject * objectCount * sizeof(std::uint32_t), kStorageUsage,
                            MemoryUse::Readback);
    if (!deviceRays) createHostRays();
  }
  frameParams = Buffer(context, sizeof(FrameParams));
  thresholds = Buffer(context, sizeof(render::ToneThresholds));
  exposureHistograms = Buffer(context, 2 * shared::kMeterBins * sizeof(std::uint32_t), kStorageUsage, MemoryUse::DeviceOnly);
  exposureResult = Buffer(context, sizeof(ExposureResult), kStorageUsage, MemoryUse::DeviceOnly);
  exposureOut = Buffer(context, sizeof(ExposureResult), kStorageUsage, MemoryUse::Readback);

  const auto lvl = static_cast<std::uint32_t>(level);
  // Constant 2 is rotate_spatial.comp's local size (the other methods'
  // shaders fix theirs and ignore it): on a CPU device fewer invocations per
  // workgroup make each barrier cheaper (docs/gpu.md, "Performance").
  std::uint32_t local = context.info().type == "cpu" ? shared::kLocalSize : shared::kGpuLocalSize;
  if (limits.spatialLocalSize) local = limits.spatialLocalSize;
  rotationInput = std::make_unique<ComputePipeline>(context, "rotation_input.comp", shared::kRotationInputBindings, 0);
  resolve = std::make_unique<ComputePipeline>(context, "resolve.comp", shared::kResolveBindings, 0);
  exposure = std::make_unique<ComputePipeline>(context, "exposure.comp", shared::kExposureBindings, 0);
  exposureReadout = std::make_unique<ComputePipeline>(context, "exposure_readout.comp", shared::kExposureBindings,
                                                      sizeof(ExposurePush));
  tonemap = std::make_unique<ComputePipeline>(context, "tonemap.comp", shared::kTonemapBindings, 0);
  if (splitsum) {
    createSplitsumPipeline();
    return;
  }
  if (fused) {
    createFusedLight(directionTable);
    // One SIMD group per workgroup on a CPU device: the workgroup's only
    // barriers (the reduction's) then switch no coroutines (docs/gpu.md).
    createFusedPipeline(limits.fusedLocalSize          ? limits.fusedLocalSize
                        : context.info().type == "cpu" ? context.subgroupSize()
                                                       : shared::kGpuLocalSize);
    return;
  }
  rotate = std::make_unique<ComputePipeline>(
      context, "rotate_" + methodName + ".comp", shared::kRotateBindings, sizeof(shared::RotationPush),
      std::vector<SpecConstant>{{shared::kSpecLevel, lvl}, {shared::kSpecThetaSamples, static_cast<std::uint32_t>(T)},
                                {shared::kSpecLocalSize, local}});
  tripleProduct = std::make_unique<ComputePipeline>(context, "triple_product.comp", shared::kTripleProductBindings,
                                                    sizeof(shared::RotationPush),
                                                    std::vector<SpecConstant>{{shared::kSpecLevel, lvl}});
  batchArgsPass = std::make_unique<ComputePipeline>(context, "batch_args.comp", shared::kBatchArgsBindings,
                                                    sizeof(shared::BatchArgsPush));
}

void VulkanRenderer::Impl::createFusedPipeline(std::uint32_t local) {
  // The texel views fused.comp reads (RGBA32F slices, light and directions;
  // R32UI visibility words).
  sliceTexels = TexelView(context, slices, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  lightTexels = TexelView(context, light, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  directionTexels = TexelView(context, directions, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  visibilityTexels = TexelView(context, visibility, VK_FORMAT_R32_UINT, sizeof(std::uint32_t));
  lobeLightTexels = TexelView(context, lobeLight, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  pointSliceTexels = TexelView(context, pointSlices, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  detailTexels = TexelView(context, details, VK_FORMAT_R32_SFLOAT, sizeof(float));

  // No scratch: a workgroup keeps only its reduction's vec3 per invocation,
  // so the dispatch may have as many groups as the device allows: 65,536 on
  // GPUs. On a CPU device each workgroup costs a launch, which the ground's
  // samples (a few loads each) do not amortise: 512 groups looping over the
  // samples took 0.21 CPU-s per frame on lavapipe where one group per sample
  // took 0.25 (default scene, 256², level 5; docs/gpu.md).
  fusedLocal = limits.fusedLocalSize ? limits.fusedLocalSize : local;
  const VkPhysicalDeviceLimits& device = context.properties().limits;
  const std::uint32_t largest = std::min(device.maxComputeWorkGroupSize[0], device.maxComputeWorkGroupInvocations);
  if (fusedLocal == 0 || (fusedLocal & (fusedLocal - 1)) != 0 || fusedLocal > largest) {
    throw std::invalid_argument("fused workgroup size " + std::to_string(fusedLocal) + ": " + context.info().name +
                                " takes a power of two from 1 to " + std::to_string(largest));
  }
  // A workgroup of one subgroup reduces with subgroupAdd: no barrier, which
  // lavapipe would compile into coroutines (shared_passes.h, kSpecSubgroupReduce).
  const bool subgroupReduce = fusedLocal == context.subgroupSize() && context.subgroupArithmetic();
  const std::size_t maxGroups = context.properties().limits.maxComputeWorkGroupCount[0];
  const std::size_t groups = context.info().type == "cpu" ? 512u : 1u << 16;
  fusedGroups = static_cast<std::uint32_t>(std::min<std::size_t>(maxGroups, groups));
  if (limits.fusedGroups) fusedGroups = std::min(fusedGroups, limits.fusedGroups);
  fusedPass = std::make_unique<ComputePipeline>(
      context, "fused.comp", fusedBindings(), sizeof(shared::FusedPush),
      std::vector<SpecConstant>{{shared::kSpecLocalSize, fusedLocal},
                                {shared::kSpecInterpolate, options.interpolateSlices ? 1u : 0u},
                                {shared::kSpecPrefilterFinest, static_cast<std::uint32_t>(std::max(prepared.lobeLight.finestLevel(), 0))},
                                {shared::kSpecSubgroupReduce, subgroupReduce ? 1u : 0u},
                                {shared::kSpecCellsTogether, limits.cellsTogether && context.subgroupBallotShuffle() ? 1u : 0u}});
}

}  // namespace haarcast::gpu

namespace haarcast::gpu {

void VulkanRenderer::Impl::createSplitsumPipeline() {
  lobeLightTexels = TexelView(context, lobeLight, VK_FORMAT_R32G32B32A32_SFLOAT, sizeof(glm::vec4));
  // One invocation per sample (splitsum.comp); the rotation-input pass sizes
  // the indirect dispatch as min(covered, fusedGroups) workgroups, and the
  // invocations stride over the samples beyond. A CPU device runs a
  // workgroup per thread: a few per core are enough.
  fusedLocal = limits.fusedLocalSize ? limits.fusedLocalSize : shared::kLocalSize;
  const std::size_t maxGroups = context.properties().limits.maxComputeWorkGroupCount[0];
  const std::size_t groups = context.info().type == "cpu" ? 64u : 4096u;
  fusedGroups = static_cast<std::uint32_t>(std::min<std::size_t>(maxGroups, groups));
  if (limits.fusedGroups) fusedGroups = std::min(fusedGroups, limits.fusedGroups);
  fusedPass = std::make_unique<ComputePipeline>(
      context, "splitsum.comp", splitsumBindings(), 0,
      std::vector<SpecConstant>{{shared::kSpecLocalSize, fusedLocal},
                                {shared::kSpecInterpolate, options.interpolateSlices ? 1u : 0u},
                                {shared::kSpecPrefilterFinest, static_cast<std::uint32_t>(prepared.lobeLight.finestLevel())}});
}

}  // namespace haarcast::gpu

namespace haarcast::gpu {

void VulkanRenderer::Impl::createHostRays() {
  // The shadow rays' scene where the host traces them: every object (the
  // ground included) at its scene pose, posed per frame (CpuRenderer::makeRays).
  std::vector<Instance> instances;
  for (const render::PreparedObject& p : prepared.objects) instances.push_back({p.mesh.get(), glm::mat4(p.pose.objectToWorld())});
  rays = std::make_unique<RayScene>(std::move(instances));
}

}  // namespace haarcast::gpu
