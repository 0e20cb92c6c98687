// Context (context.h): a renderer's command pool and fence on the
// process's shared device (engine.h), submission and memory.
#include "haarcast/gpu/context.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "haarcast/gpu/engine.h"

namespace haarcast::gpu {

std::string vkResultName(VkResult r) {
  switch (r) {
#define HAARCAST_VK_NAME(x) \
  case x: return #x;
    HAARCAST_VK_NAME(VK_SUCCESS)
    HAARCAST_VK_NAME(VK_NOT_READY)
    HAARCAST_VK_NAME(VK_TIMEOUT)
    HAARCAST_VK_NAME(VK_EVENT_SET)
    HAARCAST_VK_NAME(VK_EVENT_RESET)
    HAARCAST_VK_NAME(VK_INCOMPLETE)
    HAARCAST_VK_NAME(VK_ERROR_OUT_OF_HOST_MEMORY)
    HAARCAST_VK_NAME(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    HAARCAST_VK_NAME(VK_ERROR_INITIALIZATION_FAILED)
    HAARCAST_VK_NAME(VK_ERROR_DEVICE_LOST)
    HAARCAST_VK_NAME(VK_ERROR_MEMORY_MAP_FAILED)
    HAARCAST_VK_NAME(VK_ERROR_LAYER_NOT_PRESENT)
    HAARCAST_VK_NAME(VK_ERROR_EXTENSION_NOT_PRESENT)
    HAARCAST_VK_NAME(VK_ERROR_FEATURE_NOT_PRESENT)
    HAARCAST_VK_NAME(VK_ERROR_INCOMPATIBLE_DRIVER)
    HAARCAST_VK_NAME(VK_ERROR_TOO_MANY_OBJECTS)
    HAARCAST_VK_NAME(VK_ERROR_FORMAT_NOT_SUPPORTED)
    HAARCAST_VK_NAME(VK_ERROR_FRAGMENTED_POOL)
    HAARCAST_VK_NAME(VK_ERROR_OUT_OF_POOL_MEMORY)
    HAARCAST_VK_NAME(VK_ERROR_UNKNOWN)
#undef HAARCAST_VK_NAME
    default: return "VkResult " + std::to_string(static_cast<int>(r));
  }
}

void throwVkError(VkResult result, const char* call) {
  throw std::runtime_error(std::string(call) + " failed: " + vkResultName(result) + " (" +
                           std::to_string(static_cast<int>(result)) + ")");
}

Context::Context(const VulkanOptions& options)
    : shared_(Engine::get(EngineOptions{options.validation}).device(options.device, options.queues)),
      device_(shared_->device()),
      queueIndex_(shared_->lendQueue()),
      directInputs_(!options.stageInputs),
      validationMark_(shared_->validationLog().count()) {
  try {
    VkCommandPoolCreateInfo pool{};
    pool.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = shared_->queueFamily();
    vkCheck(vkCreateCommandPool(device_, &pool, nullptr, &pool_), "vkCreateCommandPool");
    VkFenceCreateInfo fence{};
    fence.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    vkCheck(vkCreateFence(device_, &fence, nullptr, &fence_), "vkCreateFence");
  } catch (...) {
    destroy();  // the destructor does not run for a constructor that throws
    throw;
  }
}

Context::~Context() { destroy(); }

void Context::destroy() {
  waitIdle();  // best effort: nothing to report from a destructor
  if (fence_) vkDestroyFence(device_, fence_, nullptr);
  if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
  fence_ = VK_NULL_HANDLE;
  pool_ = VK_NULL_HANDLE;
  if (queueIndex_) shared_->returnQueue(*queueIndex_);
  queueIndex_.reset();
}

void Context::waitIdle() {
  if (!inFlight_) return;
  if (vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX) == VK_SUCCESS) inFlight_ = false;
}

VkInstance Context::instance() const { return shared_->instance(); }
VkPhysicalDevice Context::physicalDevice() const { return shared_->physicalDevice(); }
VkQueue Context::queue() const { return shared_->queue(*queueIndex_); }
std::uint32_t Context::queueIndex() const { return *queueIndex_; }
std::uint32_t Context::queueFamily() const { return shared_->queueFamily(); }
const DeviceInfo& Context::info() const { return shared_->info(); }
const VkPhysicalDeviceProperties& Context::properties() const { return shared_->properties(); }
std::uint32_t Context::subgroupSize() const { return shared_->subgroupSize(); }
std::uint32_t Context::timestampValidBits() const { return shared_->timestampValidBits(); }
const VkPhysicalDeviceMemoryProperties& Context::memoryProperties() const { return shared_->memoryProperties(); }

void Context::submit(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo a{};
  a.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  a.commandPool = pool_;
  a.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  a.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  vkCheck(vkAllocateCommandBuffers(device_, &a, &cb), "vkAllocateCommandBuffers");
  struct Free {  // never frees a command buffer the device may still run (a wait that threw)
    Context& context;
    VkCommandBuffer cb;
    ~Free() {
      context.waitIdle();
      vkFreeCommandBuffers(context.device_, context.pool_, 1, &cb);
    }
  } guard{*this, cb};
  VkCommandBufferBeginInfo begin{};
  begin.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkCheck(vkBeginCommandBuffer(cb, &begin), "vkBeginCommandBuffer");
  record(cb);
  vkCheck(vkEndCommandBuffer(cb), "vkEndCommandBuffer");
  VkSubmitInfo s{};
  s.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
  s.commandBufferCount = 1;
  s.pCommandBuffers = &cb;
  waitIdle();  // a previous submission whose wait threw: its fence cannot be reset while in use
  if (inFlight_) throw std::runtime_error("Context::submit: the previous submission never finished (vkWaitForFences failed)");
  vkCheck(vkResetFences(device_, 1, &fence_), "vkResetFences");
  shared_->submit(*queueIndex_, s, fence_);  // under its queue's lock; the wait below is outside it
  ++submissions_;
  inFlight_ = true;
  vkCheck(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  inFlight_ = false;
}

std::uint32_t Context::memoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                                  VkMemoryPropertyFlags preferred) const {
  const VkPhysicalDeviceMemoryProperties& memory = shared_->memoryProperties();
  for (const VkMemoryPropertyFlags want : {required | preferred, required}) {
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
      if ((typeBits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & want) == want) return i;
    }
  }
  throw std::runtime_error("no Vulkan memory type with properties " + std::to_string(required) + " among type bits " +
                           std::to_string(typeBits) + " on " + info().name);
}

VkDeviceMemory Context::allocate(VkDeviceSize bytes, std::uint32_t typeIndex, VkMemoryAllocateFlags flags) {
  VkMemoryAllocateFlagsInfo f{};
  f.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO;
  f.flags = flags;
  VkMemoryAllocateInfo a{};
  a.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  if (flags) a.pNext = &f;
  a.allocationSize = bytes;
  a.memoryTypeIndex = typeIndex;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  vkCheck(vkAllocateMemory(device_, &a, nullptr, &memory), "vkAllocateMemory");
  ++allocations_;
  return memory;
}

void Context::free(VkDeviceMemory memory) {
  if (memory) vkFreeMemory(device_, memory, nullptr);
}

bool Context::validationEnabled() const { return shared_->validationEnabled(); }
const RayTracingSupport& Context::rayTracing() const { return shared_->rayTracing(); }
bool Context::subgroupArithmetic() const { return shared_->subgroupArithmetic(); }
bool Context::subgroupBallotShuffle() const { return shared_->subgroupBallotShuffle(); }

std::vector<std::string> Context::validationMessages() const {
  return shared_->validationLog().since(validationMark_.load());
}

void Context::clearValidationMessages() { validationMark_ = shared_->validationLog().count(); }

}  // namespace haarcast::gpu
