// What every frame does around its passes: the uniforms, and the stages
// recorded, submitted and timed (timestamps on GPUs, host time on CPU devices).

#include <array>
#include <vector>

#include "haarcast/render/exposure_meter.h"
#include "haarcast/render/tonemap.h"
#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

void VulkanRenderer::Impl::ensureQueries(std::uint32_t count) {
  if (count <= queryCapacity) return;
  if (queries) vkDestroyQueryPool(context.device(), queries, nullptr);
  queries = VK_NULL_HANDLE;
  queryCapacity = 0;
  VkQueryPoolCreateInfo q{};
  q.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
  q.queryType = VK_QUERY_TYPE_TIMESTAMP;
  q.queryCount = count;
  vkCheck(vkCreateQueryPool(context.device(), &q, nullptr, &queries), "vkCreateQueryPool");
  queryCapacity = count;
}

void VulkanRenderer::Impl::runStages(const std::vector<FrameStage>& stages, const render::FrameRequest& request,
                                     render::Frame& frame) {
  const std::size_t first = frame.stages.size();
  auto add = [&](const char* name, double seconds) {
    for (std::size_t i = first; i < frame.stages.size(); ++i) {
      if (frame.stages[i].name == name) {
        frame.stages[i].seconds += seconds;
        return;
      }
    }
    frame.stages.push_back({name, seconds});
  };
  if (!useTimestamps) {
    for (const FrameStage& stage : stages) {
      // (not a structured binding: clang 14, the fuzzing build's compiler,
      // cannot capture one in the lambda below)
      const auto& record = stage.second;
      frame.cancelled = cancelRequested();
      if (frame.cancelled) return;
      render::enterFrameStage(request, stage.first);
      const auto t = RendererClock::now();
      context.submit([&](VkCommandBuffer cb) {
        record(cb);
        computeBarrier(cb);
      });
      add(stage.first, secondsSince(t));
    }
    return;
  }
  frame.cancelled = cancelRequested();  // one submission: the frame is the batch
  if (frame.cancelled || stages.empty()) return;
  render::enterFrameStage(request, stages.front().first);
  const auto count = static_cast<std::uint32_t>(stages.size());
  ensureQueries(count + 1);
  context.submit([&](VkCommandBuffer cb) {
    vkCmdResetQueryPool(cb, queries, 0, count + 1);
    vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 0);
    for (std::uint32_t i = 0; i < count; ++i) {
      stages[i].second(cb);
      computeBarrier(cb);
      vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, i + 1);
    }
  });
  std::vector<std::uint64_t> ticks(count + 1);
  vkCheck(vkGetQueryPoolResults(context.device(), queries, 0, count + 1, (count + 1) * sizeof(std::uint64_t), ticks.data(),
                                sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
  // Only timestampValidBits of a tick count; differences are taken modulo that.
  const std::uint64_t mask = context.timestampValidBits() >= 64 ? ~std::uint64_t{0}
                                                                 : (std::uint64_t{1} << context.timestampValidBits()) - 1;
  for (std::uint32_t i = 0; i < count; ++i) {
    const std::uint64_t delta = (ticks[i + 1] - ticks[i]) & mask;
    add(stages[i].first, static_cast<double>(delta) * context.timestampPeriodNs() * 1e-9);
  }
}

void VulkanRenderer::Impl::uploadFrameUniforms(const render::FrameRequest& request, const render::ResolvedFrame& resolved) {
  FrameParams params = makeFrameParams(resolved.camera, request.width, request.height, request.lightRotation,
                                       options.environmentBackground, prepared.background[0].level());
  params.fusedGroups = fusedGroups;
  params.antialias = options.antialias ? 1u : 0u;
  frameParams.write(&params, sizeof params);
  // A fixed exposure is encoded in the thresholds; an automatic one is a
  // gain the device chooses (exposure.comp) over the thresholds of 0 stops.
  const render::ExposureControl& e = request.exposure;  // checked by render::checkFrameRequest
  const render::ToneThresholds encoding = render::tonemapThresholds(e.automatic ? 0.0 : e.stops, request.tone);
  thresholds.write(encoding.data(), sizeof encoding);
}

void VulkanRenderer::Impl::recordTonemap(VkCommandBuffer cb, const render::FrameRequest& request) {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  resolve->dispatch(cb, {groupsOf(pixels, shared::kLocalSize), 1, 1});
  computeBarrier(cb);
  const ExposurePush push = render::exposurePush(request.exposure, request.tone);
  exposure->dispatch(cb, {1, 1, 1}, &push, sizeof push);  // one workgroup reduces the frame
  computeBarrier(cb);
  tonemap->dispatch(cb, {groupsOf(pixels, shared::kLocalSize), 1, 1});
  if (request.linearImage) {
    // The pixels' radiance (the first `pixels` entries) into host memory.
    computeBarrier(cb);
    const VkBufferCopy region{0, 0, pixels * sizeof(glm::vec4)};
    vkCmdCopyBuffer(cb, radiance.handle(), radianceOut.handle(), 1, &region);
    computeBarrier(cb);
  }
}

void VulkanRenderer::Impl::finishExposure(const render::FrameRequest& request, render::Frame& frame) const {
  ExposureResult r{};
  exposureResult.read(&r, sizeof r);
  frame.logAverageLuminance = r.logAverage;
  // A fixed exposure is reported as asked (the device holds it in float).
  frame.exposureStops = request.exposure.automatic ? static_cast<double>(r.stops) : request.exposure.stops;
}

}  // namespace haarcast::gpu
