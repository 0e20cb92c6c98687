// The Vulkan device every GPU pass runs on: instance, device selection,
// one queue, memory and one-shot command submission (buffers: buffer.h).
//
// Selection (no --device): the first usable device in the order discrete GPU,
// integrated GPU, virtual GPU, CPU device (Mesa's lavapipe), other. A device
// is usable when it offers Vulkan 1.2 and one queue family with graphics and
// compute (the G-buffer rasterises, every other pass computes). A name
// substring or an index ("--device 0", "--device llvmpipe") overrides the
// order; when nothing fits, the error lists each device and why it was
// rejected.
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
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

namespace haarcast::gpu {

// Validation layers by default in debug builds; tests turn them on always.
#ifdef NDEBUG
inline constexpr bool kValidationByDefault = false;
#else
inline constexpr bool kValidationByDefault = true;
#endif

struct VulkanOptions {
  // A device index (as listDevices numbers them) or a case-insensitive
  // substring of its name; empty = the automatic order above.
  std::string device;
  // VK_LAYER_KHRONOS_validation, when installed (silently off otherwise;
  // Context::validationEnabled() tells). Any message of severity warning or
  // error is recorded (Context::validationMessages()).
  bool validation = kValidationByDefault;
  // Upload MemoryUse::DeviceInput buffers through a staging buffer even
  // where their memory could be mapped (buffer.h): the path of a discrete
  // GPU, run on any device (tests).
  bool stageInputs = false;
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
// tests use to decide whether to skip).
bool vulkanAvailable();
// Every physical device, usable or not, with the reason it is not.
// Throws std::runtime_error when no Vulkan instance can be created.
std::vector<DeviceInfo> listDevices();
// One line per device: "0: llvmpipe (…) [cpu, Vulkan 1.3.230]" plus the
// reason a device is rejected.
std::string describeDevices(const std::vector<DeviceInfo>& devices);
bool validationLayerInstalled();

class Context {
 public:
  // Throws std::runtime_error naming the problem (no device, a failed call).
  explicit Context(const VulkanOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  std::uint32_t queueFamily() const { return queueFamily_; }
  const DeviceInfo& info() const { return info_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  // Invocations a subgroup runs together (VkPhysicalDeviceSubgroupProperties):
  // the SIMD width on a CPU device (8 on lavapipe with AVX2).
  std::uint32_t subgroupSize() const { return subgroupSize_; }

  // Timestamp queries: supported on the queue, and nanoseconds per tick.
  bool timestampsSupported() const { return timestampValidBits_ > 0 && properties_.limits.timestampPeriod > 0; }
  double timestampPeriodNs() const { return properties_.limits.timestampPeriod; }
  std::uint32_t timestampValidBits() const { return timestampValidBits_; }

  // Records with `record` into a fresh primary command buffer, submits it and
  // waits for the queue to finish it.
  void submit(const std::function<void(VkCommandBuffer)>& record);

  // Memory: the type index for the requirement bits and property flags
  // (preferring `preferred` on top of `required`); throws when none fits.
  std::uint32_t memoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                           VkMemoryPropertyFlags preferred = 0) const;
  const VkPhysicalDeviceMemoryProperties& memoryProperties() const { return memory_; }
  // False when VulkanOptions::stageInputs asks for staged uploads everywhere.
  bool directInputs() const { return directInputs_; }
  // vkAllocateMemory through the context, so that allocations can be counted
  // (the renderer must not allocate per frame; a test checks it).
  VkDeviceMemory allocate(VkDeviceSize bytes, std::uint32_t typeIndex);
  void free(VkDeviceMemory memory);
  std::uint64_t allocationCount() const { return allocations_.load(); }

  bool validationEnabled() const { return messenger_ != VK_NULL_HANDLE; }
  // Validation warnings and errors seen so far (empty without validation).
  std::vector<std::string> validationMessages() const;
  void clearValidationMessages();
  void addValidationMessage(std::string message);  // for the debug callback

 private:
  void destroy();
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  std::uint32_t queueFamily_ = 0;
  std::uint32_t timestampValidBits_ = 0;
  std::uint32_t subgroupSize_ = 1;
  bool directInputs_ = true;
  DeviceInfo info_;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  std::atomic<std::uint64_t> allocations_{0};
  mutable std::mutex messagesMutex_;
  std::vector<std::string> messages_;
};

}  // namespace haarcast::gpu
