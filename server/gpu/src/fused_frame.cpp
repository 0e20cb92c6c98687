// A `fused` frame: G-buffer → rotation input (compaction, indirect arguments)
// → fused (vkCmdDispatchIndirect, no readback of the count) → tonemap, one
// command buffer on devices with timestamps.

#include <cstddef>
#include <span>

#include "haarcast/core/fused.h"

#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

render::Frame VulkanRenderer::Impl::renderFused(const render::FrameRequest& request) {
  const auto start = RendererClock::now();
  render::Frame frame;
  frame.width = request.width;
  frame.height = request.height;

  // ---- light (host): resolveFrame, as the CPU backend; its pixel form uploaded
  auto t0 = RendererClock::now();
  const render::ResolvedFrame resolved = render::resolveFrame(prepared, options, request);
  ensureResolution(request.width, request.height);
  const std::size_t objectCount = prepared.objects.size();
  for (std::size_t i = 0; i < objectCount; ++i) {
    const render::ResolvedObject& o = resolved.objects[i];
    fusedLightTexels(o.fusedLight.planes, std::span<glm::vec4>(lightTexelData).subspan(i * coefficients, coefficients));
    for (int c = 0; c < 3; ++c) objectInfo[i].rotation[c] = glm::vec4(glm::vec3(o.rotation[c]), 0.0f);
  }
  lightUpload.write(lightTexelData.data(), lightTexelData.size() * sizeof(glm::vec4));
  objects.write(objectInfo.data(), objectInfo.size() * sizeof(ObjectInfo));
  uploadFrameUniforms(request);
  frame.stages.push_back({"light", secondsSince(t0)});

  // ---- the device's part: one command buffer (timestamps) or one per stage
  const glm::dmat4 viewProj = frameViewProjection(request);
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  runStages({{"gbuffer", [&](VkCommandBuffer cb) { recordGBuffer(cb, request, viewProj); }},
             {"rotation-input",
              [&](VkCommandBuffer cb) {
                vkCmdFillBuffer(cb, counter.handle(), 0, VK_WHOLE_SIZE, 0u);
                lightUpload.record(cb);  // where the light is staged: its copy into device memory
                computeBarrier(cb);
                rotationInput->dispatch(cb, {groupsOf(pixels, 64), 1, 1});
              }},
             {"fused",
              [&](VkCommandBuffer cb) {
                fusedPass->dispatchIndirect(cb, counter, offsetof(CoverageCounter, groups));
              }},
             {"tonemap", [&](VkCommandBuffer cb) { recordTonemap(cb, request); }}},
            frame);
  if (frame.cancelled) return frame;  // stopped between stages: no images

  // ---- Results: RGBA8 always, the linear image only when asked for ----------
  frame.rgba8.resize(pixels * 4);
  rgba8.read(frame.rgba8.data(), frame.rgba8.size());
  frame.objectMask.assign(pixels, 0);
  const auto* ids = static_cast<const glm::uvec4*>(gbufIds.mapped());
  for (std::size_t p = 0; p < pixels; ++p) frame.objectMask[p] = ids[p].x != 0 ? 1 : 0;
  if (request.linearImage) {
    frame.image = io::makeImage(width, height);
    const auto* rad = static_cast<const glm::vec4*>(radiance.mapped());
    for (std::size_t p = 0; p < pixels; ++p) {
      for (std::size_t c = 0; c < 3; ++c) frame.image.rgb[3 * p + c] = rad[p][static_cast<int>(c)];
    }
  }
  finishExposure(request, frame);

  // Coefficient bytes read, counted as the CPU backend counts them: the light
  // lists, and per shaded sample core fusedPixelBytes (one slice or two, the
  // light planes, the three vertices' entries).
  std::size_t bytes = resolved.lightBytes;
  CoverageCounter count{};
  counter.read(&count, sizeof count);
  const auto* rs = static_cast<const RotationSample*>(samples.mapped());
  const auto* sh = static_cast<const ShadeSample*>(shade.mapped());
  for (std::uint32_t i = 0; i < count.covered && i < sampleCapacity; ++i) {
    std::size_t entries = 0;
    for (std::uint32_t v : sh[i].vertex) entries += v < visibilityBlocks.size() ? visibilityBlocks[v] : 0;
    const shared::SliceBlend blend =
        shared::sliceBlendAt(rs[i].thetaOut, static_cast<shared::uint>(options.thetaSamples), options.interpolateSlices ? 1u : 0u);
    // With the vertices' pixel forms, three planes of N floats replace the lists.
    bytes += fusedVertexPlanes ? fusedPixelBytes(level, blend.weight != 0.0f && blend.second != blend.first, 0) +
                                     3 * coefficients * sizeof(float)
                               : fusedPixelBytes(level, blend.weight != 0.0f && blend.second != blend.first, entries);
  }
  frame.coefficientBytes = bytes;
  frame.seconds = secondsSince(start);
  return frame;
}

}  // namespace haarcast::gpu
