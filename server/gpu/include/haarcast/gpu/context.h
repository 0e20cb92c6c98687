// A renderer's handle on the Vulkan device every GPU pass runs on: device
// selection, the queue it submits to, memory and one-shot command
// submission (buffers: buffer.h).
//
// The instance and the VkDevice are the process's (engine.h): made once,
// the device on the first Context that selects it, and lent to every
// Context, as is one of the device's queues (the least-lent:
// queue_lender.h). What a Context owns is its own: a command pool, a fence,
// the count of its allocations and its stageInputs choice. Contexts on one
// device may submit from different threads at once (submissions to one
// queue are serialised in the engine; each Context waits on its own fence),
// and those on different queues run side by side.
//
// Selection (no --device): the first usable device in the order discrete GPU,
// integrated GPU, virtual GPU, CPU device (Mesa's lavapipe), other. A device
// is usable when it offers Vulkan 1.2 and one queue family with graphics and
// compute (the G-buffer rasterises, every other pass computes). A name
// substring or an index ("--device 0", "--device llvmpipe") overrides the
// order; when nothing fits, the error lists each device and why it was
// rejected.
//
// Validation is a property of the process's instance (engine.h): on when
// the first Vulkan use of the process asked for it (VulkanOptions::validation
// of the first Context, or EngineOptions) or HAARCAST_VULKAN_VALIDATION=1 is
// set, and the validation layer is installed. A Context's validation
// messages are the instance's messages since the Context was made (or last
// cleared): with several Contexts alive at once, each also sees the others'.
//
// Every VkResult is checked where it is returned: vkCheck throws
// std::runtime_error("vkCreateDevice failed: VK_ERROR_…"), naming the call.
//
// Minimal use (what helper code and tests do):
//   gpu::Context ctx;                                   // auto-selects a device
//   gpu::Buffer in(ctx, bytes), out(ctx, bytes);         // buffer.h
//   in.upload(std::span<const float>(data));
//   gpu::ComputePipeline p(ctx, "rotate_spatial.comp", 4, 16, {{0, level}, {1, T}});  // compute.h
//   p.bind({&a, &b, &c, &d});
//   ctx.submit([&](VkCommandBuffer cb) { p.dispatch(cb, {count, 3, 1}, &push, sizeof push); });
//   out.download(std::span<float>(result));
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "haarcast/render/backend_names.h"

namespace haarcast::gpu {

// Validation layers by default in debug builds (render/backend_names.h).
inline constexpr bool kValidationByDefault = render::kValidationByDefault;

struct VulkanOptions {
  // A device index (as listDevices numbers them) or a case-insensitive
  // substring of its name; empty = the automatic order above.
  std::string device;
  // VK_LAYER_KHRONOS_validation, when installed (silently off otherwise;
  // Context::validationEnabled() tells). It counts only for the first Vulkan
  // use of the process, which creates the instance (above). Any message of
  // severity warning or error is recorded (Context::validationMessages()).
  bool validation = kValidationByDefault;
  // Upload MemoryUse::DeviceInput buffers through a staging buffer even
  // where their memory could be mapped (buffer.h): the path of a discrete
  // GPU, run on any device (tests).
  bool stageInputs = false;
  // The most queues the device is opened with (engine.h; 0 = every queue
  // of its graphics-and-compute family, at most kMaxDeviceQueues). Counts
  // only for the Context that opens the device, the first to select it.
  // One by default: on the H200 one frame fills the device, and frames on
  // queues of their own ran 0.8× as many frames a second in all as one
  // frame at a time (docs/gpu.md); more may pay where frames are small.
  std::uint32_t queues = 1;
};

// "VK_ERROR_OUT_OF_DEVICE_MEMORY" etc., or the number for unknown codes.
std::string vkResultName(VkResult result);
[[noreturn]] void throwVkError(VkResult result, const char* call);
// Throws unless result is VK_SUCCESS; `call` names the Vulkan function.
inline void vkCheck(VkResult result, const char* call) {
  if (result != VK_SUCCESS) throwVkError(result, call);
}

struct DeviceInfo {
  int index = 0;               // position in vkEnumeratePhysicalDevices
  std::string name;            // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string type;            // "discrete" | "integrated" | "virtual" | "cpu" | "other"
  std::uint32_t apiVersion = 0;
  std::string apiVersionText;  // "1.3.230"
  std::string rejected;        // empty when usable, else why not
};

// True when a Vulkan loader and at least one physical device exist (what
// tests use to decide whether to skip). Creates the process's instance
// (engine.h) if there is none yet, with validation only where
// kValidationByDefault or the environment asks for it.
bool vulkanAvailable();
// Every physical device, usable or not, with the reason it is not, from the
// process's instance (created as vulkanAvailable() does).
// Throws std::runtime_error when no Vulkan instance can be created.
std::vector<DeviceInfo> listDevices();
// One line per device: "0: llvmpipe (…) [cpu, Vulkan 1.3.230]" plus the
// reason a device is rejected.
std::string describeDevices(const std::vector<DeviceInfo>& devices);
bool validationLayerInstalled();

// Whether a device traces rays itself (VK_KHR_acceleration_structure and
// VK_KHR_ray_tracing_pipeline with their features, and buffer device
// addresses): the device-ray frame (render::RayMode, vulkan_renderer.h) and
// gpu/ray_tracing.h need it. A ray-tracing pipeline rather than ray queries
// in the compute passes, because the one data-centre GPU measured (an H100,
// driver 580) offers the pipeline and not VK_KHR_ray_query; lavapipe (Mesa
// ≥ 24.1) offers both.
struct RayTracingSupport {
  bool supported = false;
  std::string missing;  // empty when supported, else what the device lacks
  // VkPhysicalDeviceRayTracingPipelinePropertiesKHR: the shader binding
  // table's record size and alignments.
  std::uint32_t handleSize = 0, handleAlignment = 1, baseAlignment = 1;
  // VkPhysicalDeviceAccelerationStructurePropertiesKHR: scratch alignment.
  std::uint32_t scratchAlignment = 1;
};

class SharedDevice;

class Context {
 public:
  // Throws std::runtime_error naming the problem (no device, a failed call).
  explicit Context(const VulkanOptions& options = {});
  ~Context();  // waits for this Context's submission, if one is still in flight
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const;
  VkPhysicalDevice physicalDevice() const;
  VkDevice device() const { return device_; }
  // The queue lent to this Context (maybe shared with other Contexts on the
  // device): submit through submit() only (the engine serialises
  // submissions to one queue), and its index among the device's queues.
  VkQueue queue() const;
  std::uint32_t queueIndex() const;
  std::uint32_t queueFamily() const;
  const DeviceInfo& info() const;
  const VkPhysicalDeviceProperties& properties() const;
  // Invocations a subgroup runs together (VkPhysicalDeviceSubgroupProperties):
  // the SIMD width on a CPU device (8 on lavapipe with AVX2).
  std::uint32_t subgroupSize() const;
  // Whether compute shaders may use subgroup arithmetic (subgroupAdd).
  bool subgroupArithmetic() const;
  bool subgroupBallotShuffle() const;  // Engine::subgroupBallotShuffle

  const RayTracingSupport& rayTracing() const;

  // Timestamp queries: supported on the queue, and nanoseconds per tick.
  bool timestampsSupported() const { return timestampValidBits() > 0 && properties().limits.timestampPeriod > 0; }
  double timestampPeriodNs() const { return properties().limits.timestampPeriod; }
  std::uint32_t timestampValidBits() const;

  // Records with `record` into a fresh primary command buffer, submits it and
  // waits for this Context's fence (not for other Contexts' work).
  void submit(const std::function<void(VkCommandBuffer)>& record);
  // Command buffers this Context has submitted: what a test counts to see
  // that a frame is one submission.
  std::uint64_t submissionCount() const { return submissions_.load(); }
  // Waits for a submission of this Context still in flight (one whose wait
  // threw); what destructors call in place of vkDeviceWaitIdle, which would
  // wait for every renderer on the device.
  void waitIdle();

  // Memory: the type index for the requirement bits and property flags
  // (preferring `preferred` on top of `required`); throws when none fits.
  std::uint32_t memoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                           VkMemoryPropertyFlags preferred = 0) const;
  const VkPhysicalDeviceMemoryProperties& memoryProperties() const;
  // False when VulkanOptions::stageInputs asks for staged uploads everywhere.
  bool directInputs() const { return directInputs_; }
  // vkAllocateMemory through the context, so that allocations can be counted
  // (the renderer must not allocate per frame; a test checks it).
  // `flags`: VkMemoryAllocateFlags, VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT for
  // a buffer whose device address a shader or an acceleration structure reads.
  VkDeviceMemory allocate(VkDeviceSize bytes, std::uint32_t typeIndex, VkMemoryAllocateFlags flags = 0);
  void free(VkDeviceMemory memory);
  std::uint64_t allocationCount() const { return allocations_.load(); }

  // Whether the process's instance runs the validation layer.
  bool validationEnabled() const;
  // The instance's validation warnings and errors since this Context was
  // made or last cleared (empty without validation).
  std::vector<std::string> validationMessages() const;
  void clearValidationMessages();

 private:
  void destroy();
  std::shared_ptr<SharedDevice> shared_;  // the process's device: outlives this Context
  VkDevice device_ = VK_NULL_HANDLE;
  std::optional<std::uint32_t> queueIndex_;  // lent by the device until destroy()
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  bool inFlight_ = false;  // submitted, not yet waited for
  bool directInputs_ = true;
  std::atomic<std::uint64_t> allocations_{0};
  std::atomic<std::uint64_t> submissions_{0};
  std::atomic<std::uint64_t> validationMark_{0};  // ValidationLog::count() when made or cleared
};

}  // namespace haarcast::gpu
