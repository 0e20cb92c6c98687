// The shadow rays of a `fused` or `splitsum` frame on the device
// (shaders/shadow_rays.rgen, core/shared_rays.h): the same rays the host
// traces with Embree (fused_frame.cpp computeShadowMasks), from the same
// samples, so the frame needs no host work between its G-buffer and its
// RGBA8 bytes and is one submission.

#include <algorithm>
#include <cstdio>
#include <exception>
#include <stdexcept>
#include <string>

#include "haarcast/core/check.h"
#include "haarcast/core/shared_smooth.h"
#include "haarcast/render/point_lights.h"

#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

void VulkanRenderer::Impl::chooseRays() {
  const bool traces = fused || splitsum;
  const RayTracingSupport& rt = context.rayTracing();
  switch (limits.rays) {
    case render::RayMode::Host: deviceRays = false; break;
    case render::RayMode::Device:
      if (!rt.supported) {
        throw std::invalid_argument("--rays device: " + context.info().name + " cannot trace rays (" + rt.missing +
                                    "); valid here: auto, host");
      }
      deviceRays = traces;
      break;
    case render::RayMode::Auto:
      // On a GPU the device's rays; on a CPU device (lavapipe) Embree, which
      // runs on the same cores and is faster there (docs/gpu.md, "Rays").
      deviceRays = traces && rt.supported && context.info().type != "cpu";
      break;
  }
}

void VulkanRenderer::Impl::createDeviceRays() {
  try {
    setUpDeviceRays();
  } catch (const std::exception& e) {
    if (limits.rays != render::RayMode::Auto) throw;
    std::fprintf(stderr, "warning: %s: the device's rays could not be set up (%s); the host traces them\n",
                 context.info().name.c_str(), e.what());
    deviceRays = false;
    shadowRays.reset();
    accelerationStructures.reset();
    createHostRays();
  }
}

void VulkanRenderer::Impl::setUpDeviceRays() {
  std::vector<const Mesh*> meshes;
  for (const render::PreparedObject& p : prepared.objects) meshes.push_back(p.mesh.get());
  accelerationStructures = std::make_unique<AccelerationStructures>(context, meshes);
  shadowRays = std::make_unique<RayTracingPipeline>(context, RayShaders{"shadow_rays.rgen", {"shadow_rays.rmiss", "shadow_rays_hit.rmiss"}, "shadow_rays.rchit"},
                                                    shared::kRaysStorageBindings, shared::kRaysSceneBinding,
                                                    sizeof(RaysPush));
  rayObjectData.assign(prepared.objects.size(), RayObject{});
  rayObjects = Buffer(context, rayObjectData.size() * sizeof(RayObject), kStorageUsage, MemoryUse::DeviceInput);
  rayObjectsUpload = BufferUpload(context, rayObjects);
  rayFrame = Buffer(context, sizeof(RayFrame), kStorageUsage, MemoryUse::DeviceInput);
  rayFrameUpload = BufferUpload(context, rayFrame);
  // The map light, rgb and luminance per texel, for the sky the objects
  // hide (SkyOccluders::colour, ::luminance).
  const bool skyRays = groundSky() || objectSky();
  std::vector<glm::vec4> texels(1, glm::vec4(0.0f));
  if (skyRays) {
    const SphereMap& luminance = prepared.restLuminance;
    const std::array<SphereMap, 3>& colour = prepared.restLightAt(luminance.level());
    texels.resize(luminance.pixelCount());
    for (std::size_t i = 0; i < texels.size(); ++i)
      texels[i] = glm::vec4(colour[0].values()[i], colour[1].values()[i], colour[2].values()[i], luminance.values()[i]);
  }
  skyLight = Buffer(context, texels.size() * sizeof(glm::vec4), kStorageUsage, MemoryUse::DeviceInput);
  BufferUpload up(context, skyLight);
  up.write(texels.data(), texels.size() * sizeof(glm::vec4));
  up.submit();
}

void VulkanRenderer::Impl::ensureDeviceRayBuffers() {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  // The coarse grid's points, then the fine grid's (shared_rays.h).
  const int step = render::groundSkyStep(width, height);
  const int fine = static_cast<int>(shared::groundSkyFineStep(static_cast<std::uint32_t>(step)));
  const std::size_t finePoints = static_cast<std::size_t>((width - 1) / fine + 2) * static_cast<std::size_t>((height - 1) / fine + 2);
  const std::size_t gridPoints = static_cast<std::size_t>((width - 1) / step + 2) * static_cast<std::size_t>((height - 1) / step + 2) + finePoints;
  pixelSample = Buffer(context, pixels * sizeof(std::uint32_t), kStorageUsage, MemoryUse::DeviceOnly);
  skyGrid = Buffer(context, gridPoints * sizeof(float), kStorageUsage, MemoryUse::DeviceOnly);
  // The sky jobs: none without the ground's hidden sky (a one-job list, never filled).
  skyJobCapacity = static_cast<std::uint32_t>(!groundSky() ? 1 : limits.skyJobs > 0 ? limits.skyJobs : finePoints);
  skyJobs = Buffer(context, 4 * sizeof(std::uint32_t) + skyJobCapacity * sizeof(shared::SkyJob), kStorageUsage, MemoryUse::DeviceOnly);
  skyPartials = Buffer(context, std::size_t{skyJobCapacity} * shared::kSkyLanes * sizeof(float), kStorageUsage, MemoryUse::DeviceOnly);
  shadowRays->bind({{shared::kRaysShadeBinding, &shade},
                    {shared::kRaysCounterBinding, &counter},
                    {shared::kRaysPositionsBinding, &positions},
                    {shared::kRaysNormalsBinding, &normals},
                    {shared::kRaysObjectsBinding, &rayObjects},
                    {shared::kRaysFrameBinding, &rayFrame},
                    {shared::kRaysSkyLightBinding, &skyLight},
                    {shared::kRaysPixelSampleBinding, &pixelSample},
                    {shared::kRaysGridBinding, &skyGrid},
                    {shared::kRaysMasksBinding, &masks},
                    {shared::kRaysHiddenBinding, &hidden},
                    {shared::kRaysSkyJobsBinding, &skyJobs},
                    {shared::kRaysSkyPartialsBinding, &skyPartials},
                    {shared::kRaysStageListsBinding, &smoothLists}},
                   accelerationStructures->topLevel());
}

void VulkanRenderer::Impl::writeRays(const render::ResolvedFrame& resolved, const glm::vec3& eye) {
  const std::size_t objectCount = prepared.objects.size();
  HC_CHECK_EQ(resolved.objects.size(), objectCount);
  const bool groundSky = this->groundSky();
  const bool hides = objectSky();
  std::size_t occluder = 0;  // SkyOccluders::occluders: every object but the ground, in order
  for (std::size_t i = 0; i < objectCount; ++i) {
    const render::PreparedObject& p = prepared.objects[i];
    const render::ResolvedObject& o = resolved.objects[i];
    RayObject& r = rayObjectData[i];
    r.toWorld = glm::mat4(o.objectToWorld);
    for (int c = 0; c < 3; ++c) r.rotation[c] = glm::vec4(glm::vec3(glm::mat3(o.rotation)[c]), 0.0f);
    r.shift = p.shadowShift * static_cast<float>(o.scale);
    r.flags = (p.ground ? shared::kObjectGround : 0u) | (p.lobePath ? shared::kObjectLobePath : 0u);
    r.mask = shared::rayMaskOf(static_cast<std::uint32_t>(i));
    r.occluder = (groundSky || hides) && !p.ground ? 1u : 0u;
    r.sphere = glm::vec4(0.0f);
    if (r.occluder) {
      HC_CHECK_LT(occluder, resolved.skyOccluders.occluders.size());
      r.sphere = resolved.skyOccluders.occluders[occluder++];
    }
  }
  if (groundSky || hides) HC_CHECK_EQ(occluder, resolved.skyOccluders.occluders.size());
  rayObjectsUpload.write(rayObjectData.data(), rayObjectData.size() * sizeof(RayObject));

  RayFrame& f = rayFrameData;
  f = RayFrame{};
  const std::size_t lights = resolved.pointLightDirections.size();
  HC_CHECK_LE(lights, std::size_t{shared::kMaxPointLights});
  for (std::size_t k = 0; k < lights; ++k) f.lightDirections[k] = glm::vec4(resolved.pointLightDirections[k], 0.0f);
  f.lights = static_cast<std::uint32_t>(lights);
  f.objects = static_cast<std::uint32_t>(objectCount);
  f.eye = glm::vec4(eye, 0.0f);
  f.width = static_cast<std::uint32_t>(width);
  f.height = static_cast<std::uint32_t>(height);
  f.gridStep = static_cast<std::uint32_t>(render::groundSkyStep(width, height));
  f.gridColumns = static_cast<std::uint32_t>(width - 1) / f.gridStep + 2u;
  f.gridRows = static_cast<std::uint32_t>(height - 1) / f.gridStep + 2u;
  f.fineStep = shared::groundSkyFineStep(f.gridStep);
  f.fineColumns = static_cast<std::uint32_t>(width - 1) / f.fineStep + 2u;
  f.fineRows = static_cast<std::uint32_t>(height - 1) / f.fineStep + 2u;
  f.antialias = options.antialias ? 1u : 0u;
  f.groundSky = groundSky ? 1u : 0u;
  f.objectSky = hides ? 1u : 0u;
  f.skyJobCapacity = skyJobCapacity;
  if (groundSky || hides) {
    const render::SkyOccluders& sky = resolved.skyOccluders;
    f.sky = glm::vec4(sky.normal, static_cast<float>(sky.total));
    for (int c = 0; c < 3; ++c) f.toEnvironment[c] = glm::vec4(sky.toEnvironment[c], 0.0f);
    f.luminanceLevel = static_cast<std::uint32_t>(prepared.restLuminance.level());
    f.minShare = static_cast<float>(sky.minShare);
  }
  rayFrameUpload.write(&f, sizeof f);

  posesData.resize(objectCount);
  for (std::size_t i = 0; i < objectCount; ++i) posesData[i] = glm::mat4(resolved.objects[i].objectToWorld);
}

bool VulkanRenderer::Impl::hiddenPerStage() const {
  return deviceRays && objectSky() && options.smoothSumTolerance > 0.0f;
}

RaysPush VulkanRenderer::Impl::raysPush(shared::uint phase, shared::uint stage) const {
  RaysPush push{};
  push.phase = phase;
  push.stagedHidden = hiddenPerStage() ? 1u : 0u;
  push.stage = stage;
  push.ownLists = smoothOwnLists();
  return push;
}

// The hidden sky of the samples smooth-sum stage `stage` sums itself, between
// its two `fused` dispatches (after its first, before its second).
void VulkanRenderer::Impl::recordStageHidden(VkCommandBuffer cb, shared::uint stage) {
  rayTracingBarrier(cb);
  const RaysPush push = raysPush(shared::kRaysPhaseHidden, stage);
  const auto entries = shared::smoothStagePixels(stage, static_cast<shared::uint>(width), static_cast<shared::uint>(height));
  shadowRays->trace(cb, kRaysLaunchWidth, groupsOf(entries, kRaysLaunchWidth), &push, sizeof push);
  rayTracingBarrier(cb);
}

// Sky jobs: the launch that lists them (`phase`, across × down; the
// frame's part `listed`), their rays over kSkyLanes invocations a job, then
// their lanes' sums (part `traced`).
void VulkanRenderer::Impl::recordSkyJobs(VkCommandBuffer cb, std::uint32_t phase, std::uint32_t across,
                                         std::uint32_t down, const char* listed, const char* traced) {
  vkCmdFillBuffer(cb, skyJobs.handle(), 0, sizeof(std::uint32_t), 0u);  // the list's count
  rayTracingBarrier(cb);
  RaysPush push = raysPush(phase);
  shadowRays->trace(cb, across, down, &push, sizeof push);
  rayTracingBarrier(cb);
  markPart(cb, listed);
  // Every job's lanes at once up to kSkyJobsInFlight; beyond, each invocation takes further jobs.
  const std::uint32_t inFlight = std::min(skyJobCapacity, shared::kSkyJobsInFlight);
  push.phase = shared::kRaysPhaseSkyRays;
  shadowRays->trace(cb, shared::kSkyLanes * shared::kSkyJobsAcross, groupsOf(inFlight, shared::kSkyJobsAcross), &push,
                    sizeof push);
  rayTracingBarrier(cb);
  push.phase = shared::kRaysPhaseSkySums;
  shadowRays->trace(cb, kRaysLaunchWidth, groupsOf(skyJobCapacity, kRaysLaunchWidth), &push, sizeof push);
  rayTracingBarrier(cb);
  markPart(cb, traced);
}

void VulkanRenderer::Impl::recordDeviceRays(VkCommandBuffer cb) {
  rayObjectsUpload.record(cb);
  rayFrameUpload.record(cb);
  rayTracingBarrier(cb);  // rotation-input's samples and the uploads, for the launches
  markPart(cb, "uploads");
  accelerationStructures->recordTopLevel(cb, posesData);  // ends with a barrier for the launches
  markPart(cb, "top level");
  // The samples' launches: kRaysLaunchWidth wide, as many rows as the
  // capacity needs; invocations past the covered count return at once.
  const std::uint32_t rows = groupsOf(sampleCapacity, kRaysLaunchWidth);
  if (rayFrameData.groundSky) {
    vkCmdFillBuffer(cb, pixelSample.handle(), 0, VK_WHOLE_SIZE, ~0u);
    rayTracingBarrier(cb);
    const RaysPush push = raysPush(shared::kRaysPhaseCentres);
    shadowRays->trace(cb, kRaysLaunchWidth, rows, &push, sizeof push);
    rayTracingBarrier(cb);
    markPart(cb, "ground centres");
    recordSkyJobs(cb, shared::kRaysPhaseGrid, rayFrameData.gridColumns, rayFrameData.gridRows, "ground grid points",
                  "ground grid rays");
    // Reads the coarse grid: after its sums.
    recordSkyJobs(cb, shared::kRaysPhaseFineGrid, rayFrameData.fineColumns, rayFrameData.fineRows,
                  "ground fine grid points", "ground fine grid rays");
    // The samples' words; the ground's samples that no grid cell blends take sky jobs of their own.
    recordSkyJobs(cb, shared::kRaysPhaseMasks, kRaysLaunchWidth, rows, "masks", "ground's own sky rays");
    return;
  }
  const RaysPush push = raysPush(shared::kRaysPhaseMasks);
  shadowRays->trace(cb, kRaysLaunchWidth, rows, &push, sizeof push);
  rayTracingBarrier(cb);
  markPart(cb, "masks");
}

}  // namespace haarcast::gpu
