// A frame of the rotating methods (haar, spatial, matrix, table): G-buffer,
// rotation input, then rotation and triple product batch by batch (the batch
// count comes from the covered-pixel count, read back after rotation input),
// then tonemap; each stage its own submission.

#include <algorithm>
#include <functional>
#include <stdexcept>
#include <vector>

#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

render::Frame VulkanRenderer::Impl::renderRotating(const render::FrameRequest& request) {
  render::checkFrameRequest(request, prepared.objects.size());
  const auto start = RendererClock::now();
  ensureResolution(request.width, request.height);
  const std::size_t objectCount = prepared.objects.size();
  const std::size_t k = request.lightCoefficients ? request.lightCoefficients : options.lightCoefficients;
  render::Frame frame;
  frame.width = request.width;
  frame.height = request.height;
  std::size_t bytes = 0;

  // ---- light (host): the same code as the CPU backend ----------------------
  auto t0 = RendererClock::now();
  std::vector<SparseHaar> lights;
  lights.reserve(objectCount * 3);
  for (std::size_t i = 0; i < objectCount; ++i) {
    const glm::dmat3 rot = poseOf(request, i).rotation();
    for (SparseHaar& s : render::lightInObjectFrame(prepared.light, rot, request.lightRotation, k)) {
      lights.push_back(std::move(s));
    }
    for (int c = 0; c < 3; ++c) objectInfo[i].rotation[c] = glm::vec4(glm::vec3(rot[c]), 0.0f);
  }
  const std::vector<glm::uvec4> lightPacked = packSparseLists(lights, level);
  lightUpload.write(lightPacked.data(), lightPacked.size() * sizeof(glm::uvec4));
  bytes += (lightPacked.size() - lights.size()) * sizeof(glm::uvec4);
  objects.write(objectInfo.data(), objectInfo.size() * sizeof(ObjectInfo));
  uploadFrameUniforms(request);
  frame.stages.push_back({"light", secondsSince(t0)});

  const glm::dmat4 viewProj = frameViewProjection(request);

  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  // Each stage is its own submission, timed as the member comment says.
  auto timed = [&](double& seconds, const std::function<void(VkCommandBuffer)>& record) {
    const auto t = RendererClock::now();
    context.submit([&](VkCommandBuffer cb) {
      if (useTimestamps) {
        vkCmdResetQueryPool(cb, queries, 0, 2);
        vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 0);
      }
      record(cb);
      computeBarrier(cb);
      if (useTimestamps) vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, 1);
    });
    if (!useTimestamps) {
      seconds += secondsSince(t);
      return;
    }
    std::uint64_t ticks[2] = {0, 0};
    vkCheck(vkGetQueryPoolResults(context.device(), queries, 0, 2, sizeof ticks, ticks, sizeof(std::uint64_t),
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "vkGetQueryPoolResults");
    if (ticks[1] > ticks[0]) seconds += static_cast<double>(ticks[1] - ticks[0]) * context.timestampPeriodNs() * 1e-9;
  };
  double gbuffer = 0, rotInput = 0, rotation = 0, product = 0, tone = 0;

  // ---- gbuffer ------------------------------------------------------------------
  timed(gbuffer, [&](VkCommandBuffer cb) { recordGBuffer(cb, request, viewProj); });

  // ---- rotation-input -----------------------------------------------------------
  timed(rotInput, [&](VkCommandBuffer cb) {
    vkCmdFillBuffer(cb, counter.handle(), 0, VK_WHOLE_SIZE, 0u);
    lightUpload.record(cb);  // where the light is staged: its copy into device memory
    computeBarrier(cb);
    rotationInput->dispatch(cb, {groupsOf(pixels, 64), 1, 1});
  });
  std::uint32_t covered = 0;
  counter.read(&covered, sizeof covered);
  if (covered > pixels) throw std::logic_error("rotation-input reported more covered pixels than the frame has");

  // ---- rotation and triple-product, batch by batch --------------------------------
  const std::size_t batches = (covered + batch - 1) / batch;
  lastBatches = batches;
  for (std::size_t b = 0; b < batches; ++b) {
    BatchPush push;
    push.first = static_cast<std::uint32_t>(b * batch);
    push.count = static_cast<std::uint32_t>(std::min<std::size_t>(batch, covered - b * batch));
    // The contract: one workgroup per (sample, channel).
    timed(rotation, [&](VkCommandBuffer cb) { rotate->dispatch(cb, {push.count, 3, 1}, &push, sizeof push); });
    timed(product, [&](VkCommandBuffer cb) {
      tripleProduct->dispatch(cb, {groupsOf(3 * std::size_t{push.count}, 64), 1, 1}, &push, sizeof push);
    });
  }

  // ---- tonemap ------------------------------------------------------------------
  timed(tone, [&](VkCommandBuffer cb) { tonemap->dispatch(cb, {groupsOf(pixels, 64), 1, 1}); });

  // ---- Results ---------------------------------------------------------------
  frame.image = io::makeImage(width, height);
  frame.objectMask.assign(pixels, 0);
  frame.rgba8.resize(pixels * 4);
  {
    const auto* rad = static_cast<const glm::vec4*>(radiance.mapped());
    const auto* ids = static_cast<const glm::uvec4*>(gbufIds.mapped());
    for (std::size_t p = 0; p < pixels; ++p) {
      for (std::size_t c = 0; c < 3; ++c) frame.image.rgb[3 * p + c] = rad[p][static_cast<int>(c)];
      frame.objectMask[p] = ids[p].x != 0 ? 1 : 0;
    }
    rgba8.read(frame.rgba8.data(), frame.rgba8.size());
  }

  frame.stages.push_back({"gbuffer", gbuffer});
  frame.stages.push_back({"rotation-input", rotInput});
  frame.stages.push_back({"rotation", rotation});
  frame.stages.push_back({"triple-product", product});
  frame.stages.push_back({"tonemap", tone});

  // Coefficient bytes read: the light lists (above), and per covered pixel and
  // channel the rotation's data and the three vertices' visibility lists, in
  // the GPU's own formats (16-byte blocks).
  {
    const auto* sh = static_cast<const ShadeSample*>(shade.mapped());
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
