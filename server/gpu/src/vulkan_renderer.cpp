// VulkanRenderer (vulkan_renderer.h): construction, the facade over Impl
// (vulkan_renderer_impl.h) and the last frame's intermediate data for tests.

#include "haarcast/gpu/vulkan_renderer.h"

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>

#include "haarcast/gpu/engine.h"
#include "haarcast/gpu/shaders.h"

#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

// ------------------------------------------------------------------ setup

void VulkanRenderer::Impl::checkOptions(const render::RenderOptions& options) {
  render::checkRenderOptions(options);
  const bool fusedPass = options.method == RotationMethod::Fused || options.method == RotationMethod::Splitsum;
  if (fusedPass) {
    checkFusedLevel(options.level);  // 2–7: its scratch need not fit in shared memory (splitsum reads no maps of it)
  } else if (options.level < kMinGpuLevel || options.level > kMaxGpuLevel) {
    throw std::invalid_argument("the Vulkan backend takes map levels " + std::to_string(kMinGpuLevel) + " to " +
                                std::to_string(kMaxGpuLevel) + " (got " + std::to_string(options.level) +
                                "): a rotation workgroup keeps one map in shared memory, and a level-6 map is the "
                                "16 KiB every Vulkan device guarantees");
  }
  const std::string name(haarcast::methodName(options.method));
  const std::string shader = fusedPass ? name + ".comp" : "rotate_" + name + ".comp";
  if (embeddedShader(shader).empty()) {
    throw std::invalid_argument("rotation method \"" + name + "\" has no Vulkan shader in this build (shaders/" +
                                shader + " is missing)");
  }
}

VulkanRenderer::Impl::Impl(std::shared_ptr<const render::PreparedScene> scene, const render::RenderOptions& o,
                           const VulkanOptions& vulkan, const VulkanRendererLimits& l)
    : options(o), limits(l), preparedScene(std::move(scene)), prepared(*preparedScene), context(vulkan) {
  fused = options.method == RotationMethod::Fused;
  splitsum = options.method == RotationMethod::Splitsum;
  methodName = std::string(haarcast::methodName(options.method));
  level = options.level;
  coefficients = static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level));
  chooseRays();
  uploadScene();
  if (deviceRays) createDeviceRays();
  createGraphicsPipeline();
  useTimestamps = context.timestampsSupported() && context.properties().limits.timestampComputeAndGraphics &&
                  context.info().type != "cpu";
}

VulkanRenderer::Impl::~Impl() {
  VkDevice device = context.device();
  // This renderer's own work only (the device is shared with every other
  // renderer, engine.h): every submission is waited for, unless its wait threw.
  context.waitIdle();
  releaseResolution();
  if (queries) vkDestroyQueryPool(device, queries, nullptr);
  if (gbufferPool) vkDestroyDescriptorPool(device, gbufferPool, nullptr);
  if (gbufferPipeline) vkDestroyPipeline(device, gbufferPipeline, nullptr);
  if (gbufferLayout) vkDestroyPipelineLayout(device, gbufferLayout, nullptr);
  if (gbufferSetLayout) vkDestroyDescriptorSetLayout(device, gbufferSetLayout, nullptr);
  if (renderPass) vkDestroyRenderPass(device, renderPass, nullptr);
}

render::Frame VulkanRenderer::Impl::render(const render::FrameRequest& request) {
  struct Polled {  // request.cancelled, for runStages, for this frame only
    Impl& impl;
    ~Polled() { impl.cancelled = nullptr; }
  } polled{*this};
  cancelled = &request.cancelled;
  return fused || splitsum ? renderFused(request) : renderRotating(request);
}

// ------------------------------------------------------------------ facade

VulkanRenderer::VulkanRenderer(const render::Scene& scene, const render::RenderOptions& options,
                               const VulkanOptions& vulkan, const render::RenderProgress& progress,
                               const VulkanRendererLimits& limits) {
  Impl::checkOptions(options);
  // The device first (it throws when there is none), then the scene,
  // prepared once for every slot.
  const std::shared_ptr<SharedDevice> device =
      Engine::get(EngineOptions{vulkan.validation}).device(vulkan.device, vulkan.queues);
  const auto prepared = std::make_shared<const render::PreparedScene>(render::prepareScene(scene, options, progress));
  std::size_t slots = limits.framesInFlight;
  // A CPU device's frames share its cores; a GPU's overlap one frame's
  // host work with another's passes (each slot's Context is lent the
  // least-lent queue).
  if (slots == 0) slots = device->info().type == "cpu" ? 1 : kDefaultGpuFramesInFlight;
  // Each slot uploads its own copy of the scene's data and compiles the
  // same pipelines (the driver's cache makes the second compile a lookup).
  // The further slots' progress is one stage of its own, so that the
  // build's fractions never go back.
  slots_.push_back(std::make_unique<Impl>(prepared, options, vulkan, limits));
  while (slots_.size() < slots) {
    if (progress) progress("frame slots", slots_.size(), slots);
    slots_.push_back(std::make_unique<Impl>(prepared, options, vulkan, limits));
  }
  if (progress && slots > 1) progress("frame slots", slots, slots);
  busy_.assign(slots_.size(), false);
}

VulkanRenderer::~VulkanRenderer() = default;

VulkanRenderer::Impl& VulkanRenderer::last() const {
  std::lock_guard lock(mutex_);
  return *slots_[last_];
}

render::Frame VulkanRenderer::render(const render::FrameRequest& request) {
  std::size_t slot = 0;
  {
    std::unique_lock lock(mutex_);
    freed_.wait(lock, [&] { return std::find(busy_.begin(), busy_.end(), false) != busy_.end(); });
    slot = static_cast<std::size_t>(std::find(busy_.begin(), busy_.end(), false) - busy_.begin());
    busy_[slot] = true;
    peak_ = std::max(peak_, ++inFlight_);
  }
  struct Release {
    VulkanRenderer& r;
    std::size_t slot;
    ~Release() {
      {
        std::lock_guard lock(r.mutex_);
        r.busy_[slot] = false;
        --r.inFlight_;
        r.last_ = slot;
      }
      r.freed_.notify_one();
    }
  } release{*this, slot};
  return slots_[slot]->render(request);
}

std::size_t VulkanRenderer::peakFramesInFlight() const {
  std::lock_guard lock(mutex_);
  return peak_;
}

std::vector<std::uint32_t> VulkanRenderer::slotQueues() const {
  std::vector<std::uint32_t> queues;
  for (const auto& slot : slots_) queues.push_back(slot->context.queueIndex());
  return queues;
}

std::string VulkanRenderer::deviceName() const { return slots_.front()->context.info().name; }
std::string VulkanRenderer::rays() const {
  const Impl& impl = *slots_.front();
  if (!impl.fused && !impl.splitsum) return "none";
  return impl.deviceRays ? "device" : "host";
}
const render::RenderOptions& VulkanRenderer::options() const { return slots_.front()->options; }
std::size_t VulkanRenderer::objectCount() const { return slots_.front()->prepared.objects.size(); }
std::vector<int> VulkanRenderer::objectLevels() const { return slots_.front()->prepared.objectLevels(); }
std::vector<int> VulkanRenderer::pointLightLevels() const { return slots_.front()->prepared.pointLightLevels(); }
std::vector<std::string> VulkanRenderer::objectPlans() const { return slots_.front()->prepared.objectPlans(); }
Context& VulkanRenderer::context() { return last().context; }
const render::PreparedScene& VulkanRenderer::prepared() const { return *slots_.front()->preparedScene; }
std::size_t VulkanRenderer::batchSamples() const { return last().batch; }
std::size_t VulkanRenderer::batchesLastFrame() const { return last().lastBatches; }

namespace {
template <class T>
std::vector<T> readAll(Context& context, const Buffer& b, std::size_t count) {
  std::vector<T> out(count);
  readBack(context, b, out.data(), count * sizeof(T));
  return out;
}
}  // namespace

std::vector<glm::uvec4> VulkanRenderer::gbufferIds() const {
  return readAll<glm::uvec4>(last().context, last().gbufIds, static_cast<std::size_t>(last().width) * static_cast<std::size_t>(last().height));
}
std::vector<glm::vec4> VulkanRenderer::gbufferNormals() const {
  return readAll<glm::vec4>(last().context, last().gbufNormals, static_cast<std::size_t>(last().width) * static_cast<std::size_t>(last().height));
}
std::vector<glm::vec4> VulkanRenderer::gbufferPositions() const {
  return readAll<glm::vec4>(last().context, last().gbufPositions, static_cast<std::size_t>(last().width) * static_cast<std::size_t>(last().height));
}
std::vector<RotationSample> VulkanRenderer::rotationSamples() const {
  Impl& impl = last();
  const std::uint32_t covered = impl.counterOut.handle() ? impl.coveredSamples() : 0;
  return readAll<RotationSample>(impl.context, impl.samples, covered);
}
std::vector<ShadeSample> VulkanRenderer::shadeSamples() const {
  Impl& impl = last();
  const std::uint32_t covered = impl.counterOut.handle() ? impl.coveredSamples() : 0;
  return readAll<ShadeSample>(impl.context, impl.shade, covered);
}
std::vector<std::uint32_t> VulkanRenderer::shadowWords() const {
  Impl& impl = last();
  if (!impl.masks.handle()) return {};
  const std::uint32_t covered = impl.counterOut.handle() ? impl.coveredSamples() : 0;
  return readAll<std::uint32_t>(impl.context, impl.masks, covered);
}
std::vector<HiddenLight> VulkanRenderer::hiddenLights() const {
  Impl& impl = last();
  if (!impl.objectSky() || !impl.hidden.handle()) return {};
  const std::uint32_t covered = impl.counterOut.handle() ? impl.coveredSamples() : 0;
  return readAll<HiddenLight>(impl.context, impl.hidden, covered);
}
std::vector<glm::vec4> VulkanRenderer::lightTexels() const {
  Impl& impl = last();
  if (!impl.fused) return {};
  return readAll<glm::vec4>(impl.context, impl.light, impl.fusedLightTexelCount);
}
std::vector<ObjectInfo> VulkanRenderer::objectInfos() const {
  Impl& impl = last();
  if (!impl.fused) return {};
  return readAll<ObjectInfo>(impl.context, impl.objects, impl.objectInfo.size());
}
std::size_t VulkanRenderer::lightsMadeLastFrame() const { return last().lightsMadeLastFrame; }
std::vector<std::uint32_t> VulkanRenderer::edgeWords() const {
  if (!last().options.antialias) return {};
  return readAll<std::uint32_t>(last().context, last().edges, static_cast<std::size_t>(last().width) * static_cast<std::size_t>(last().height));
}

std::unique_ptr<render::Renderer> makeVulkanRenderer(const render::Scene& scene, const render::RenderOptions& options,
                                                     const VulkanOptions& vulkan, const render::RenderProgress& progress,
                                                     const VulkanRendererLimits& limits) {
  return std::make_unique<VulkanRenderer>(scene, options, vulkan, progress, limits);
}

}  // namespace haarcast::gpu
