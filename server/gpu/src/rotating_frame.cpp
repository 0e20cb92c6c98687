// A frame of the rotating methods (haar, spatial, matrix, table): G-buffer,
// rotation input (compaction, then every batch's indirect arguments), then
// rotation and triple product batch by batch (vkCmdDispatchIndirect), then
// tonemap — one command buffer on devices with timestamps, no readback of
// the covered count until the frame is done.

#include <algorithm>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

render::Frame VulkanRenderer::Impl::renderRotating(const render::FrameRequest& request) {
  const auto start = RendererClock::now();
  // ---- light (host): resolveFrame, as the CPU backend (it checks the request).
  auto t0 = RendererClock::now();
  render::enterFrameStage(request, "light");
  render::ResolvedFrame resolved = render::resolveFrame(prepared, options, request);
  ensureResolution(request.width, request.height);
  const std::size_t objectCount = prepared.objects.size();
  render::Frame frame;
  frame.width = request.width;
  frame.height = request.height;
  std::size_t bytes = 0;

  std::vector<SparseHaar> lights;
  lights.reserve(objectCount * 3);
  for (std::size_t i = 0; i < objectCount; ++i) {
    render::ResolvedObject& o = resolved.objects[i];
    for (SparseHaar& s : o.light) lights.push_back(std::move(s));
    for (int c = 0; c < 3; ++c) objectInfo[i].rotation[c] = glm::vec4(glm::vec3(o.rotation[c]), 0.0f);
  }
  const std::vector<glm::uvec4> lightPacked = packSparseLists(lights, level);
  lightUpload.write(lightPacked.data(), lightPacked.size() * sizeof(glm::uvec4));
  bytes += (lightPacked.size() - lights.size()) * sizeof(glm::uvec4);
  objects.write(objectInfo.data(), objectInfo.size() * sizeof(ObjectInfo));
  uploadFrameUniforms(request, resolved);
  frame.stages.push_back({"light", secondsSince(t0)});

  // ---- the device's part: one command buffer (timestamps) or one per stage.
  // Every batch the resolution can need is recorded; batch_args.comp sizes
  // each from the covered count, and batches past it dispatch nothing, so
  // the host does not read the count back mid-frame.
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  std::vector<FrameStage> stages;
  stages.emplace_back("gbuffer", [&](VkCommandBuffer cb) { recordGBuffer(cb, resolved); });
  stages.emplace_back("rotation-input", [&](VkCommandBuffer cb) {
    vkCmdFillBuffer(cb, counter.handle(), 0, VK_WHOLE_SIZE, 0u);
    lightUpload.record(cb);  // where the light is staged: its copy into device memory
    computeBarrier(cb);
    rotationInput->dispatch(cb, {groupsOf(pixels, shared::kLocalSize), 1, 1});
    recordCounterCopy(cb);
    computeBarrier(cb);
    shared::BatchArgsPush sizes{};
    sizes.batch = static_cast<std::uint32_t>(batch);
    sizes.batches = static_cast<std::uint32_t>(maxBatches);
    batchArgsPass->dispatch(cb, {groupsOf(maxBatches, shared::kLocalSize), 1, 1}, &sizes, sizeof sizes);
  });
  std::vector<shared::RotationPush> pushes(maxBatches);
  for (std::size_t b = 0; b < maxBatches; ++b) {
    pushes[b].first = static_cast<std::uint32_t>(b * batch);
    pushes[b].count = static_cast<std::uint32_t>(batch);  // the shaders stop at the covered count
    // The contract: one workgroup per (sample, channel).
    stages.emplace_back("rotation", [&, b](VkCommandBuffer cb) {
      rotate->dispatchIndirect(cb, batchArgs, b * sizeof(DispatchArgs), &pushes[b], sizeof(shared::RotationPush));
    });
    stages.emplace_back("triple-product", [&, b](VkCommandBuffer cb) {
      tripleProduct->dispatchIndirect(cb, batchArgs, (maxBatches + b) * sizeof(DispatchArgs), &pushes[b],
                                      sizeof(shared::RotationPush));
    });
  }
  stages.emplace_back("tonemap", [&](VkCommandBuffer cb) { recordTonemap(cb, request); });
  runStages(stages, request, frame);
  if (frame.cancelled) return frame;  // stopped between batches: no images

  const std::uint32_t covered = coveredSamples();
  lastBatches = (covered + batch - 1) / batch;

  // ---- Results ---------------------------------------------------------------
  frame.rgba8.resize(pixels * 4);
  rgba8.read(frame.rgba8.data(), frame.rgba8.size());
  if (request.linearImage) readLinearImage(frame);
  finishExposure(request, frame);

  // Coefficient bytes read: the light lists (above), and per covered pixel and
  // channel the rotation's data and the three vertices' visibility lists, in
  // the GPU's own formats (16-byte blocks). These methods are the
  // comparisons' (not the service's default), so the samples are copied
  // back to count them; `fused` counts its bytes on the device.
  {
    const ShadeSample* sh = readShadeSamples(covered);
    for (std::uint32_t i = 0; i < covered; ++i) {
      std::size_t visBlocks = 0;
      for (std::uint32_t v : sh[i].vertex) visBlocks += v < visibilityBlocks.size() ? visibilityBlocks[v] : 0;
      const std::size_t object = sh[i].object < objectCount ? sh[i].object : 0;
      bytes += 3 * (rotationBytesPerChannel + methodBytesPerChannel[object] + visBlocks * sizeof(glm::uvec4));
    }
  }
  frame.coefficientBytes = bytes;
  frame.seconds = secondsSince(start);
  return frame;
}

}  // namespace haarcast::gpu
