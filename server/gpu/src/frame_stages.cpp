// What every frame does around its passes: the uniforms, and the stages
// recorded, submitted and timed (timestamps on GPUs, host time on CPU devices).

#include <array>
#include <vector>

#include "haarcast/core/check.h"
#include "haarcast/io/image.h"
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
  if (!useTimestamps && limits.oneSubmission) {
    // One submission on a CPU device: timed on the host as one stage.
    frame.cancelled = cancelRequested();
    if (frame.cancelled || stages.empty()) return;
    render::enterFrameStage(request, stages.front().first);
    const auto t = RendererClock::now();
    context.submit([&](VkCommandBuffer cb) {
      for (const FrameStage& stage : stages) {
        stage.second(cb);
        computeBarrier(cb);
      }
    });
    add("device", secondsSince(t));
    return;
  }
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
  // The stages' boundaries, then the parts' marks (markPart), up to kMaxPartMarks.
  ensureQueries(count + 1 + kMaxPartMarks);
  partMarks.clear();
  nextPartQuery = count + 1;
  partQueryEnd = count + 1 + kMaxPartMarks;  // the queries reset below: the pool may hold more
  struct Recording {  // markPart records only inside this submission
    Impl& impl;
    ~Recording() { impl.markStage = -1; }
  } recording{*this};
  context.submit([&](VkCommandBuffer cb) {
    vkCmdResetQueryPool(cb, queries, 0, count + 1 + kMaxPartMarks);
    vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, queries, 0);
    for (std::uint32_t i = 0; i < count; ++i) {
      markStage = static_cast<int>(i);
      stages[i].second(cb);
      computeBarrier(cb);
      vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, i + 1);
    }
    markStage = -1;
  });
  const std::uint32_t written = nextPartQuery;
  std::vector<std::uint64_t> ticks(written);
  vkCheck(vkGetQueryPoolResults(context.device(), queries, 0, written, written * sizeof(std::uint64_t), ticks.data(),
                                sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
  // Only timestampValidBits of a tick count; differences are taken modulo that.
  const std::uint64_t mask = context.timestampValidBits() >= 64 ? ~std::uint64_t{0}
                                                                 : (std::uint64_t{1} << context.timestampValidBits()) - 1;
  const auto seconds = [&](std::uint32_t from, std::uint32_t to) {
    return static_cast<double>((ticks[to] - ticks[from]) & mask) * context.timestampPeriodNs() * 1e-9;
  };
  for (std::uint32_t i = 0; i < count; ++i) {
    add(stages[i].first, seconds(i, i + 1));
    // Its parts: each from the mark before it (the stage's start first), the rest to its end.
    std::uint32_t from = i;
    for (const PartMark& m : partMarks) {
      if (m.stage != i) continue;
      frame.parts.push_back({std::string(stages[i].first) + ": " + m.name, seconds(from, m.query)});
      from = m.query;
    }
    if (from != i) frame.parts.push_back({std::string(stages[i].first) + ": rest", seconds(from, i + 1)});
  }
}

void VulkanRenderer::Impl::markPart(VkCommandBuffer cb, const char* part) {
  if (markStage < 0 || nextPartQuery >= partQueryEnd) return;
  vkCmdWriteTimestamp(cb, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, queries, nextPartQuery);
  partMarks.push_back({part, static_cast<std::uint32_t>(markStage), nextPartQuery});
  ++nextPartQuery;
}

void VulkanRenderer::Impl::uploadFrameUniforms(const render::FrameRequest& request, const render::ResolvedFrame& resolved) {
  FrameParams params = makeFrameParams(resolved.camera, request.width, request.height, resolved.lightRotation,
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
  markPart(cb, "resolve");
  // The meter: histograms over many workgroups, then one invocation's read-out.
  vkCmdFillBuffer(cb, exposureHistograms.handle(), 0, VK_WHOLE_SIZE, 0u);
  computeBarrier(cb);
  exposure->dispatch(cb, {groupsOf(pixels, shared::kExposureLocalSize * shared::kExposurePixelsPerInvocation), 1, 1});
  computeBarrier(cb);
  const ExposurePush push = render::exposurePush(request.exposure, request.tone);
  exposureReadout->dispatch(cb, {1, 1, 1}, &push, sizeof push);
  computeBarrier(cb);
  markPart(cb, "exposure");
  tonemap->dispatch(cb, {groupsOf(pixels, shared::kLocalSize), 1, 1});
  computeBarrier(cb);
  markPart(cb, "tonemap");
  // What the host reads: the exposure's outcome, and on request the
  // pixels' radiance (the first `pixels` entries) and ids (the object mask).
  const VkBufferCopy result{0, 0, sizeof(ExposureResult)};
  vkCmdCopyBuffer(cb, exposureResult.handle(), exposureOut.handle(), 1, &result);
  if (request.linearImage) {
    const VkBufferCopy image{0, 0, pixels * sizeof(glm::vec4)};
    vkCmdCopyBuffer(cb, radiance.handle(), radianceOut.handle(), 1, &image);
    const VkBufferCopy ids{0, 0, pixels * sizeof(glm::uvec4)};
    vkCmdCopyBuffer(cb, gbufIds.handle(), idsOut.handle(), 1, &ids);
  }
  computeBarrier(cb);
}

void VulkanRenderer::Impl::readLinearImage(render::Frame& frame) const {
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  frame.image = io::makeImage(width, height);
  frame.objectMask.assign(pixels, 0);
  const auto* rad = static_cast<const glm::vec4*>(radianceOut.mapped());
  const auto* ids = static_cast<const glm::uvec4*>(idsOut.mapped());
  for (std::size_t p = 0; p < pixels; ++p) {
    for (std::size_t c = 0; c < 3; ++c) frame.image.rgb[3 * p + c] = rad[p][static_cast<int>(c)];
    frame.objectMask[p] = ids[p].x != 0 ? 1 : 0;
  }
}

void VulkanRenderer::Impl::recordCounterCopy(VkCommandBuffer cb) {
  computeBarrier(cb);
  const VkBufferCopy region{0, 0, sizeof(CoverageCounter)};
  vkCmdCopyBuffer(cb, counter.handle(), counterOut.handle(), 1, &region);
}

std::uint32_t VulkanRenderer::Impl::coveredSamples() const {
  CoverageCounter count{};
  counterOut.read(&count, sizeof count);
  HC_CHECK_LE(count.covered, sampleCapacity);  // rotation-input emits at most one sample per slot
  return count.covered;
}

const ShadeSample* VulkanRenderer::Impl::readShadeSamples(std::uint32_t covered) {
  if (covered != 0) {
    context.submit([&](VkCommandBuffer cb) {
      computeBarrier(cb);
      const VkBufferCopy region{0, 0, covered * sizeof(ShadeSample)};
      vkCmdCopyBuffer(cb, shade.handle(), shadeOut.handle(), 1, &region);
      computeBarrier(cb);
    });
  }
  return static_cast<const ShadeSample*>(shadeOut.mapped());
}

void VulkanRenderer::Impl::finishExposure(const render::FrameRequest& request, render::Frame& frame) const {
  ExposureResult r{};
  exposureOut.read(&r, sizeof r);
  frame.logAverageLuminance = r.logAverage;
  // A fixed exposure is reported as asked (the device holds it in float).
  frame.exposureStops = request.exposure.automatic ? static_cast<double>(r.stops) : request.exposure.stops;
}

}  // namespace haarcast::gpu
