// The process's Vulkan engine: one VkInstance, and one VkDevice per
// physical device, made once and lent to every Context (context.h), as
// pbrt-v4's GPUInit makes its device once per process.
//
// Why once: an instance and a device are the costly handles, and drivers
// bound them. On NVIDIA vkCreateInstance fails after about 40 instances in
// one process, and a server that rebuilds renderers from its LRU would make
// them without bound. A renderer keeps what is its own: a command pool, a
// fence, buffers, pipelines (Context and VulkanRenderer).
//
// What is shared and how it is kept safe:
//   - The instance, created on the first Engine::get() (a Context,
//     vulkanAvailable(), listDevices()); its physical devices are listed once.
//   - One SharedDevice per physical device, opened the first time a Context
//     selects it and kept until the process ends: VkDevice, its queues,
//     properties and memory properties. Vulkan calls on a VkDevice are
//     thread-safe except where an object needs external synchronisation; of
//     the shared objects only the queues do, so every vkQueueSubmit goes
//     through SharedDevice::submit, which holds that queue's mutex around
//     that call alone. Each Context waits on its own fence, outside the lock,
//     and never calls vkDeviceWaitIdle or vkQueueWaitIdle (either would wait
//     for the other renderers' work and need a queue's lock).
//   - Queues: the device is opened with VulkanOptions::queues of the
//     Context that opens it (one by default; 0 = every queue of its
//     graphics-and-compute family, at most kMaxDeviceQueues), and each
//     Context is lent one for its lifetime, the least-lent
//     (queue_lender.h): frames of different Contexts on different queues
//     run side by side, where on one queue every barrier waits for the
//     frames submitted before it. lavapipe offers one queue; NVIDIA's
//     family has 16. Whether side by side pays is the device's and the
//     frame's: on the H200 a 1280×720 frame fills the device, and four on
//     four queues made 0.8× the frames of one at a time (docs/gpu.md).
//   - Lifetime: a Context holds its SharedDevice, and a SharedDevice holds
//     the instance (shared_ptr). The engine is a function-local static: it is
//     destroyed at exit before the Vulkan loader's own destructors run (the
//     loader is unloaded after every atexit destructor), and it only drops
//     its references, so a device is destroyed when the last Context on it is,
//     and the instance after its last device.
//
// Validation: the instance has VK_LAYER_KHRONOS_validation (when installed)
// when the call that creates it asks for it (EngineOptions::validation; a
// Context passes VulkanOptions::validation) or when the environment sets
// HAARCAST_VULKAN_VALIDATION=1. It cannot be turned on later: a Context that
// asks for validation from an instance made without it runs without, and
// Context::validationEnabled() says so. The GPU tests create the engine with
// validation before anything else (tests/unit/gpu/gpu_test_util.h). Messages
// of severity warning and error go to one ValidationLog per instance.
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "haarcast/gpu/context.h"
#include "haarcast/gpu/queue_lender.h"

namespace haarcast::gpu {

// The validation messages of the process's instance, numbered from 0 in the
// order they came. Only the latest kKept are kept (a long-running server
// with validation on must not grow without bound); count() counts them all.
// Thread-safe: the layer calls add() from whichever thread made the call.
class ValidationLog {
 public:
  static constexpr std::size_t kKept = 1024;
  void add(std::string message);
  // Messages recorded so far; the mark a reader keeps to read what comes after.
  std::uint64_t count() const;
  // The kept messages numbered `mark` and later.
  std::vector<std::string> since(std::uint64_t mark) const;

 private:
  mutable std::mutex mutex_;
  std::deque<std::string> kept_;
  std::uint64_t count_ = 0;  // every message ever added; kept_ holds the last kept_.size()
};

// The instance and its debug messenger, destroyed together (after every
// SharedDevice made from it).
class VulkanInstance;

// The most queues a device is opened with: more than the frames a server
// has in flight on it.
inline constexpr std::uint32_t kMaxDeviceQueues = 16;

// One physical device, opened once per process and shared by every Context
// that selects it.
class SharedDevice {
 public:
  // `queues`: the most queues to open (0 = kMaxDeviceQueues); the family's
  // count bounds it.
  SharedDevice(std::shared_ptr<VulkanInstance> instance, VkPhysicalDevice physical, DeviceInfo info,
               std::uint32_t queues);
  ~SharedDevice();  // vkDestroyDevice: no Context holds it any more
  SharedDevice(const SharedDevice&) = delete;
  SharedDevice& operator=(const SharedDevice&) = delete;

  VkInstance instance() const;
  VkPhysicalDevice physicalDevice() const { return physical_; }
  VkDevice device() const { return device_; }
  // Queue `index`, for queries only: submissions go through submit().
  VkQueue queue(std::uint32_t index) const { return queues_.at(index); }
  std::uint32_t queueCount() const { return static_cast<std::uint32_t>(queues_.size()); }
  std::uint32_t queueFamily() const { return queueFamily_; }
  // The queue a new Context submits to, lent until returnQueue (queue_lender.h).
  std::uint32_t lendQueue() { return static_cast<std::uint32_t>(lender_.lend()); }
  void returnQueue(std::uint32_t index) { lender_.giveBack(index); }
  // Contexts each queue is lent to now.
  std::vector<std::size_t> queuesLent() const { return lender_.lent(); }
  std::uint32_t timestampValidBits() const { return timestampValidBits_; }
  std::uint32_t subgroupSize() const { return subgroupSize_; }
  bool subgroupArithmetic() const { return subgroupArithmetic_; }
  // Arithmetic, ballot and shuffle subgroup operations in compute shaders.
  bool subgroupBallotShuffle() const { return subgroupBallotShuffle_; }
  const DeviceInfo& info() const { return info_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memoryProperties() const { return memory_; }
  bool validationEnabled() const;
  ValidationLog& validationLog() const;
  // Ray tracing (context.h, RayTracingSupport): enabled on the device when
  // it offers it, else why not.
  const RayTracingSupport& rayTracing() const { return rayTracing_; }

  // vkQueueSubmit on queue `index`, under its mutex (a queue needs
  // external synchronisation); the caller waits on its own `fence` after.
  void submit(std::uint32_t index, const VkSubmitInfo& submit, VkFence fence);

 private:
  std::shared_ptr<VulkanInstance> instance_;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  DeviceInfo info_;
  VkDevice device_ = VK_NULL_HANDLE;
  std::vector<VkQueue> queues_;
  std::unique_ptr<std::mutex[]> queueMutexes_;  // one per queue
  QueueLender lender_;
  std::uint32_t queueFamily_ = 0;
  std::uint32_t timestampValidBits_ = 0;
  std::uint32_t subgroupSize_ = 1;
  bool subgroupArithmetic_ = false;
  bool subgroupBallotShuffle_ = false;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_{};
  RayTracingSupport rayTracing_;
};

struct EngineOptions {
  // Counts only on the call that creates the engine (see above).
  bool validation = kValidationByDefault;
};

class Engine {
 public:
  // The process's engine, created on the first call (thread-safe).
  // Throws std::runtime_error when no instance can be created (no Vulkan
  // loader or driver); a later call tries again.
  static Engine& get(const EngineOptions& options = {});

  VkInstance instance() const;
  bool validationEnabled() const;
  ValidationLog& validationLog() const;
  // Every physical device, usable or not, with the reason it is not (as
  // listed when the engine was created).
  const std::vector<DeviceInfo>& devices() const { return infos_; }
  // The device `selector` picks (VulkanOptions::device: an index, a name
  // substring, or empty for the automatic order of context.h), opened on the
  // first request for it, with at most `queues` queues (0 = kMaxDeviceQueues;
  // only the request that opens it counts). Throws std::runtime_error listing
  // every device and why it was rejected when none fits. Thread-safe.
  std::shared_ptr<SharedDevice> device(const std::string& selector, std::uint32_t queues = 1);

  // Successful vkCreateInstance and vkCreateDevice calls in this process:
  // what tests check to see that the handles are made once.
  static std::uint64_t instancesCreated();
  static std::uint64_t devicesCreated();

  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;

 private:
  explicit Engine(const EngineOptions& options);
  ~Engine();  // drops the engine's references; live Contexts keep theirs

  std::shared_ptr<VulkanInstance> instance_;
  std::vector<VkPhysicalDevice> physical_;
  std::vector<DeviceInfo> infos_;
  std::mutex devicesMutex_;
  std::vector<std::shared_ptr<SharedDevice>> opened_;  // per physical device, null until selected
};

}  // namespace haarcast::gpu
