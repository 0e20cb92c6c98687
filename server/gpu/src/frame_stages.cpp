// What every frame does around its passes: the uniforms, and the stages
// recorded, submitted and timed (timestamps on GPUs, host time on CPU devices).

#include <array>
#include <vector>

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

void VulkanRenderer::Impl::runStages(const std::vector<FrameStage>& stages, render::Frame& frame) {
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
    for (const auto& [name, record] : stages) {
      frame.cancelled = cancelRequested();
      if (frame.cancelled) return;
      const auto t = RendererClock::now();
      context.submit([&](VkCommandBuffer cb) {
        record(cb);
        computeBarrier(cb);
      });
      add(name, secondsSince(t));
    }
    return;
  }
  frame.cancelled = cancelRequested();  // one submission: the frame is the batch
  if (frame.cancelled) return;
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

namespace {
double provisionalStops(const render::ExposureControl& exposure) {
  return exposure.automatic ? exposure.previousStops.value_or(0.0) : exposure.stops;
}
}  // namespace

void VulkanRenderer::Impl::uploadFrameUniforms(const render::FrameRequest& request) {
  const double stops = provisionalStops(request.exposure);
  FrameParams params = makeFrameParams(request.camera, request.width, request.height, request.lightRotation,
                                       options.environmentBackground, prepared.background[0].level());
  params.fusedGroups = fusedGroups;
  frameParams.write(&params, sizeof params);
  const std::array<float, 256> encoding = render::tonemapThresholds(stops);
  thresholds.write(encoding.data(), sizeof encoding);
}

void VulkanRenderer::Impl::finishExposure(const render::FrameRequest& request, render::Frame& frame) {
  const double provisional = provisionalStops(request.exposure);
  frame.exposureStops = provisional;
  if (!request.exposure.automatic) return;
  // The linear image the frame read back, else a copy of the mapped radiance.
  io::RgbImage mapped;
  if (frame.image.rgb.empty()) {
    const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
    mapped = io::makeImage(width, height);
    const auto* rad = static_cast<const glm::vec4*>(radiance.mapped());
    for (std::size_t p = 0; p < pixels; ++p) {
      for (std::size_t c = 0; c < 3; ++c) mapped.rgb[3 * p + c] = rad[p][static_cast<int>(c)];
    }
  }
  const io::RgbImage& linear = frame.image.rgb.empty() ? mapped : frame.image;
  frame.logAverageLuminance = render::frameLogAverage(linear, frame.objectMask);
  frame.exposureStops = render::applyExposure(request.exposure, frame.logAverageLuminance);
  if (frame.exposureStops != provisional) frame.rgba8 = render::tonemapRgba8(linear, frame.exposureStops);
}

}  // namespace haarcast::gpu
