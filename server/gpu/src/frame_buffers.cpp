// The images and buffers of one resolution, allocated when it changes and
// reused by every frame at it (a frame allocates no device memory).

#include <algorithm>

#include "haarcast/core/shared_smooth.h"

#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

DeviceImage VulkanRenderer::Impl::createImage(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect,
                                              std::uint32_t w, std::uint32_t h) {
  VkDevice device = context.device();
  DeviceImage out;
  VkImageCreateInfo ic{};
  ic.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
  ic.imageType = VK_IMAGE_TYPE_2D;
  ic.format = format;
  ic.extent = {w, h, 1};
  ic.mipLevels = 1;
  ic.arrayLayers = 1;
  ic.samples = VK_SAMPLE_COUNT_1_BIT;
  ic.tiling = VK_IMAGE_TILING_OPTIMAL;
  ic.usage = usage;
  ic.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  vkCheck(vkCreateImage(device, &ic, nullptr, &out.image), "vkCreateImage");
  try {
    VkMemoryRequirements req{};
    vkGetImageMemoryRequirements(device, out.image, &req);
    out.memory = context.allocate(req.size, context.memoryType(req.memoryTypeBits, 0, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT));
    vkCheck(vkBindImageMemory(device, out.image, out.memory, 0), "vkBindImageMemory");
    VkImageViewCreateInfo vc{};
    vc.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vc.image = out.image;
    vc.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vc.format = format;
    vc.subresourceRange = {aspect, 0, 1, 0, 1};
    vkCheck(vkCreateImageView(device, &vc, nullptr, &out.view), "vkCreateImageView");
  } catch (...) {
    destroyImage(out);
    throw;
  }
  return out;
}

void VulkanRenderer::Impl::destroyImage(DeviceImage& image) {
  VkDevice device = context.device();
  if (image.view) vkDestroyImageView(device, image.view, nullptr);
  if (image.image) vkDestroyImage(device, image.image, nullptr);
  context.free(image.memory);
  image = DeviceImage{};
}

VulkanRenderer::Impl::GBufferTarget VulkanRenderer::Impl::createTarget(std::uint32_t w, std::uint32_t h) {
  GBufferTarget t;
  t.width = w;
  t.height = h;
  try {
    constexpr VkImageUsageFlags colourUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    t.normal = createImage(kNormalFormat, colourUsage, VK_IMAGE_ASPECT_COLOR_BIT, w, h);
    t.ids = createImage(kIdsFormat, colourUsage, VK_IMAGE_ASPECT_COLOR_BIT, w, h);
    t.position = createImage(kPositionFormat, colourUsage, VK_IMAGE_ASPECT_COLOR_BIT, w, h);
    t.depth = createImage(kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT, w, h);
    const VkImageView views[4] = {t.normal.view, t.ids.view, t.position.view, t.depth.view};
    VkFramebufferCreateInfo fb{};
    fb.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
    fb.renderPass = renderPass;
    fb.attachmentCount = 4;
    fb.pAttachments = views;
    fb.width = w;
    fb.height = h;
    fb.layers = 1;
    vkCheck(vkCreateFramebuffer(context.device(), &fb, nullptr, &t.framebuffer), "vkCreateFramebuffer");
  } catch (...) {
    destroyTarget(t);
    throw;
  }
  return t;
}

void VulkanRenderer::Impl::destroyTarget(GBufferTarget& t) {
  if (t.framebuffer) vkDestroyFramebuffer(context.device(), t.framebuffer, nullptr);
  for (DeviceImage* i : {&t.normal, &t.ids, &t.position, &t.depth}) destroyImage(*i);
  t = GBufferTarget{};
}

void VulkanRenderer::Impl::releaseResolution() {
  destroyTarget(target);
  destroyTarget(subTarget);
  maskUpload = BufferUpload();
  hiddenUpload = BufferUpload();
  for (Buffer* b : {&gbufIds, &gbufNormals, &gbufPositions, &samples, &shade, &counter, &counterOut, &shadeOut, &radiance,
                    &rgba8, &rotated, &radianceOut, &idsOut, &batchArgs, &subIds, &subNormals, &edges, &masks, &hidden, &pixelSample, &skyGrid,
                    &skyJobs, &skyPartials,
                    &smoothSums, &smoothLists}) {
    *b = Buffer();
  }
  width = height = 0;
  batch = maxBatches = sampleCapacity = 0;
}

shared::uint VulkanRenderer::Impl::smoothOwnLists() const {
  return shared::smoothListOffset(0u, static_cast<shared::uint>(width), static_cast<shared::uint>(height)) +
         static_cast<shared::uint>(sampleCapacity);
}

void VulkanRenderer::Impl::ensureResolution(int w, int h) {
  if (w == width && h == height) return;
  releaseResolution();
  width = w;
  height = h;
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  const auto uw = static_cast<std::uint32_t>(w), uh = static_cast<std::uint32_t>(h);
  target = createTarget(uw, uh);
  // The passes' own buffers are device-local (DeviceOnly); what the host
  // reads is a Readback copy (cached system memory, gpu/memory.h): the RGBA8
  // image, the counter, and on request the linear image and the ids.
  gbufIds = Buffer(context, pixels * sizeof(glm::uvec4), kStorageUsage, MemoryUse::DeviceOnly);
  gbufNormals = Buffer(context, pixels * sizeof(glm::vec4), kStorageUsage, MemoryUse::DeviceOnly);
  gbufPositions = Buffer(context, pixels * sizeof(glm::vec4), kStorageUsage, MemoryUse::DeviceOnly);
  edges = Buffer(context, pixels * sizeof(std::uint32_t), kStorageUsage, MemoryUse::DeviceOnly);
  if (options.antialias) {
    // The sub-samples: the pixel centres of the frame at twice the resolution (shared_layout.h).
    subTarget = createTarget(2 * uw, 2 * uh);
    subIds = Buffer(context, shared::kSubsamples * pixels * sizeof(glm::uvec4), kStorageUsage, MemoryUse::DeviceOnly);
    subNormals = Buffer(context, shared::kSubsamples * pixels * sizeof(glm::vec4), kStorageUsage, MemoryUse::DeviceOnly);
    sampleCapacity = shared::kSubsamples * pixels;
  } else {
    subIds = Buffer(context, sizeof(std::uint32_t), kStorageUsage, MemoryUse::DeviceOnly);
    subNormals = Buffer(context, sizeof(std::uint32_t), kStorageUsage, MemoryUse::DeviceOnly);
    sampleCapacity = pixels;
  }
  samples = Buffer(context, sampleCapacity * sizeof(RotationSample), kStorageUsage, MemoryUse::DeviceOnly);
  shade = Buffer(context, sampleCapacity * sizeof(ShadeSample), kStorageUsage, MemoryUse::DeviceOnly);
  // Where the host reads samples: copies of the covered ones (readShadeSamples).
  shadeOut = Buffer(context, sampleCapacity * sizeof(ShadeSample), kStorageUsage, MemoryUse::Readback);
  // The covered-pixel count and `fused`'s indirect dispatch arguments.
  counter = Buffer(context, sizeof(CoverageCounter), kStorageUsage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                   MemoryUse::DeviceOnly);
  counterOut = Buffer(context, sizeof(CoverageCounter), kStorageUsage, MemoryUse::Readback);
  // Per pixel, then (antialiasing) per sub-sample slot (shared_layout.h subsampleSlot).
  radiance = Buffer(context, (options.antialias ? 1 + shared::kSubsamples : 1) * pixels * sizeof(glm::vec4),
                    kStorageUsage, MemoryUse::DeviceOnly);
  // fused's smooth sum: pixel q's sum and object, then its mirror direction.
  smoothSums = Buffer(context, (fused ? 2 * pixels : 1) * sizeof(glm::vec4), kStorageUsage, MemoryUse::DeviceOnly);
  // fused's stage lists (shared_smooth.h): the header, every stage's pixels after the grid's, then stage 0's
  // samples, as many as can be covered; then as much again for each stage's samples that sum their own.
  // Read as indirect dispatches too.
  smoothLists = Buffer(context, (fused ? 2 * smoothOwnLists() : 1) * sizeof(std::uint32_t),
                       kStorageUsage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, MemoryUse::DeviceOnly);
  // The one image every frame reads back, written once by the tonemap pass.
  rgba8 = Buffer(context, pixels * sizeof(std::uint32_t), kStorageUsage, MemoryUse::Readback);
  radianceOut = Buffer(context, pixels * sizeof(glm::vec4), kStorageUsage, MemoryUse::Readback);
  idsOut = Buffer(context, pixels * sizeof(glm::uvec4), kStorageUsage, MemoryUse::Readback);

  using namespace shared;  // the passes' binding names (shared_passes.h)
  rotationInput->bind({{kRotationInputFrameBinding, &frameParams},
                       {kRotationInputObjectsBinding, &objects},
                       {kRotationInputIdsBinding, &gbufIds},
                       {kRotationInputNormalsBinding, &gbufNormals},
                       {kRotationInputTrianglesBinding, &triangles},
                       {kRotationInputSamplesBinding, &samples},
                       {kRotationInputShadeBinding, &shade},
                       {kRotationInputCounterBinding, &counter},
                       {kRotationInputSubIdsBinding, &subIds},
                       {kRotationInputSubNormalsBinding, &subNormals},
                       {kRotationInputEdgesBinding, &edges}});
  resolve->bind({{kResolveFrameBinding, &frameParams},
                 {kResolveIdsBinding, &gbufIds},
                 {kResolveRadianceBinding, &radiance},
                 {kResolveBackgroundBinding, &background},
                 {kResolveEdgesBinding, &edges}});
  for (ComputePipeline* pass : {exposure.get(), exposureReadout.get()}) {
    pass->bind({{kExposureFrameBinding, &frameParams},
                {kExposureIdsBinding, &gbufIds},
                {kExposureRadianceBinding, &radiance},
                {kExposureResultBinding, &exposureResult},
                {kExposureHistogramsBinding, &exposureHistograms}});
  }
  tonemap->bind({{kTonemapFrameBinding, &frameParams},
                 {kTonemapRadianceBinding, &radiance},
                 {kTonemapRgba8Binding, &rgba8},
                 {kTonemapThresholdsBinding, &thresholds},
                 {kTonemapExposureBinding, &exposureResult}});
  if (fused || splitsum) {
    // Each sample's point-light mask, written by the host every frame (the
    // frame's "shadow-rays" stage) and read by the fused pass.
    // On the device, the ray-generation shader writes them instead (device_rays.cpp).
    // Likewise the sky other objects hide from each sample, where they can.
    const std::size_t hiddenRecords = objectSky() ? sampleCapacity : 1;
    if (deviceRays) {
      masks = Buffer(context, sampleCapacity * sizeof(std::uint32_t), kStorageUsage, MemoryUse::DeviceOnly);
      hidden = Buffer(context, hiddenRecords * sizeof(HiddenLight), kStorageUsage, MemoryUse::DeviceOnly);
      ensureDeviceRayBuffers();
    } else {
      masks = Buffer(context, sampleCapacity * sizeof(std::uint32_t), kStorageUsage, MemoryUse::DeviceInput);
      maskUpload = BufferUpload(context, masks);
      hidden = Buffer(context, hiddenRecords * sizeof(HiddenLight), kStorageUsage, MemoryUse::DeviceInput);
      hiddenUpload = BufferUpload(context, hidden);
    }
    if (splitsum) {
      fusedPass->bind({{kSplitsumSamplesBinding, &samples},
                       {kSplitsumShadeBinding, &shade},
                       {kSplitsumObjectsBinding, &objects},
                       {kSplitsumCounterBinding, &counter},
                       {kSplitsumMasksBinding, &masks},
                       {kSplitsumLobesBinding, &lobes},
                       {kSplitsumLobeLightTexelsBinding, &lobeLightTexels},
                       {kSplitsumRadianceBinding, &radiance}});
      return;
    }
    fusedPass->bind({{kFusedSamplesBinding, &samples},
                     {kFusedShadeBinding, &shade},
                     {kFusedObjectsBinding, &objects},
                     {kFusedSliceTexelsBinding, &sliceTexels},
                     {kFusedLightTexelsBinding, &lightTexels},
                     {kFusedVisibilityTexelsBinding, &visibilityTexels},
                     {kFusedDirectionTexelsBinding, &directionTexels},
                     {kFusedPointLightsBinding, &pointLights},
                     {kFusedRadianceBinding, &radiance},
                     {kFusedCounterBinding, &counter},
                     {kFusedMasksBinding, &masks},
                     {kFusedSliceEnergyBinding, &sliceEnergy},
                     {kFusedLobesBinding, &lobes},
                     {kFusedLobeLightTexelsBinding, &lobeLightTexels},
                     {kFusedPointSliceTexelsBinding, &pointSliceTexels},
                     {kFusedDetailTexelsBinding, &detailTexels},
                     {kFusedSliceCountsBinding, &sliceCounts},
                     {kFusedHiddenBinding, &hidden},
                     {kFusedSmoothBinding, &smoothSums},
                     {kFusedStageListsBinding, &smoothLists}});
    return;
  }

  // The batch: as many covered pixels as the rotated buffer holds within the
  // budget, the device's storage-buffer range and one dispatch's group count.
  const VkPhysicalDeviceLimits& lim = context.properties().limits;
  const std::size_t perSample = 3 * coefficients * sizeof(float);
  const std::size_t range = std::min<std::size_t>(kRotatedBudget, lim.maxStorageBufferRange);
  batch = std::min({sampleCapacity, range / perSample, static_cast<std::size_t>(lim.maxComputeWorkGroupCount[0]),
                    static_cast<std::size_t>(lim.maxComputeWorkGroupCount[0]) * shared::kLocalSize / 3});
  if (limits.batchSamples) batch = std::min(batch, limits.batchSamples);
  batch = std::max<std::size_t>(batch, 1);
  maxBatches = (sampleCapacity + batch - 1) / batch;
  rotated = Buffer(context, batch * perSample, kStorageUsage, MemoryUse::DeviceOnly);
  batchArgs = Buffer(context, 2 * maxBatches * sizeof(DispatchArgs), kStorageUsage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                     MemoryUse::DeviceOnly);

  rotate->bind({{kRotateSamplesBinding, &samples},
                {kRotateSlicesBinding, &slices},
                {kRotateMethodDataBinding, &methodData},
                {kRotateRotatedBinding, &rotated}});
  tripleProduct->bind({{kTripleProductShadeBinding, &shade},
                       {kTripleProductRotatedBinding, &rotated},
                       {kTripleProductLightBinding, &light},
                       {kTripleProductVisibilityBinding, &visibility},
                       {kTripleProductRadianceBinding, &radiance},
                       {kTripleProductCounterBinding, &counter}});
  batchArgsPass->bind({{kBatchArgsCounterBinding, &counter}, {kBatchArgsArgsBinding, &batchArgs}});
}

}  // namespace haarcast::gpu
