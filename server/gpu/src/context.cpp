#include "haarcast/gpu/context.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace haarcast::gpu {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr std::uint32_t kRequiredApi = VK_API_VERSION_1_2;

std::string versionText(std::uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

std::string typeName(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}

// Lower rank = preferred (discrete > integrated > virtual > CPU > other).
int typeRank(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool layerInstalled(const char* name) {
  std::uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  return std::any_of(layers.begin(), layers.end(),
                     [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

bool instanceExtensionAvailable(const char* name) {
  std::uint32_t count = 0;
  if (vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkExtensionProperties> exts(count);
  if (vkEnumerateInstanceExtensionProperties(nullptr, &count, exts.data()) != VK_SUCCESS) return false;
  return std::any_of(exts.begin(), exts.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

VkInstance createInstance(bool validation) {
  VkApplicationInfo app{};
  app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
  app.pApplicationName = "haarcast";
  app.applicationVersion = VK_MAKE_API_VERSION(0, 0, 1, 0);
  app.pEngineName = "haarcast";
  app.apiVersion = kRequiredApi;
  std::vector<const char*> layers, extensions;
  if (validation) {
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  VkInstanceCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  vkCheck(vkCreateInstance(&info, nullptr, &instance), "vkCreateInstance");
  return instance;
}

// A queue family with graphics and compute (the G-buffer and the passes
// share one queue), or nothing.
std::optional<std::uint32_t> findQueueFamily(VkPhysicalDevice device, std::uint32_t* timestampBits = nullptr) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  for (std::uint32_t i = 0; i < count; ++i) {
    const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    if ((families[i].queueFlags & need) == need) {
      if (timestampBits) *timestampBits = families[i].timestampValidBits;
      return i;
    }
  }
  return std::nullopt;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
  std::uint32_t count = 0;
  vkCheck(vkEnumeratePhysicalDevices(instance, &count, nullptr), "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> devices(count);
  vkCheck(vkEnumeratePhysicalDevices(instance, &count, devices.data()), "vkEnumeratePhysicalDevices");
  devices.resize(count);
  return devices;
}

DeviceInfo describe(VkPhysicalDevice device, int index) {
  VkPhysicalDeviceProperties p{};
  vkGetPhysicalDeviceProperties(device, &p);
  DeviceInfo info;
  info.index = index;
  info.name = p.deviceName;
  info.type = typeName(p.deviceType);
  info.apiVersion = p.apiVersion;
  info.apiVersionText = versionText(p.apiVersion);
  if (p.apiVersion < kRequiredApi) {
    info.rejected = "Vulkan " + info.apiVersionText + " < 1.2";
  } else if (!findQueueFamily(device)) {
    info.rejected = "no queue family with both graphics and compute";
  } else if (p.limits.maxComputeSharedMemorySize < 16384) {
    info.rejected = "compute shared memory " + std::to_string(p.limits.maxComputeSharedMemorySize) +
                    " bytes < 16 KiB (the rotation shaders need 16 KiB at level 6)";
  } else if (p.limits.maxColorAttachments < 3) {
    info.rejected = "fewer than 3 colour attachments (the G-buffer has 3)";
  }
  return info;
}

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT && data && data->pMessage) {
    static_cast<Context*>(user)->addValidationMessage(data->pMessage);
  }
  return VK_FALSE;  // never abort the call: the test reports the message
}

}  // namespace

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

bool validationLayerInstalled() { return layerInstalled(kValidationLayer); }

bool vulkanAvailable() {
  try {
    VkInstance instance = createInstance(false);
    std::uint32_t count = 0;
    const VkResult r = vkEnumeratePhysicalDevices(instance, &count, nullptr);
    vkDestroyInstance(instance, nullptr);
    return r == VK_SUCCESS && count > 0;
  } catch (const std::exception&) {
    return false;
  }
}

std::vector<DeviceInfo> listDevices() {
  VkInstance instance = createInstance(false);
  std::vector<DeviceInfo> out;
  try {
    const auto devices = physicalDevices(instance);
    for (std::size_t i = 0; i < devices.size(); ++i) out.push_back(describe(devices[i], static_cast<int>(i)));
  } catch (...) {
    vkDestroyInstance(instance, nullptr);
    throw;
  }
  vkDestroyInstance(instance, nullptr);
  return out;
}

std::string describeDevices(const std::vector<DeviceInfo>& devices) {
  if (devices.empty()) return "  (no Vulkan physical devices)\n";
  std::string s;
  for (const DeviceInfo& d : devices) {
    s += "  " + std::to_string(d.index) + ": " + d.name + " [" + d.type + ", Vulkan " + d.apiVersionText + "]";
    if (!d.rejected.empty()) s += " rejected: " + d.rejected;
    s += "\n";
  }
  return s;
}

Context::Context(const VulkanOptions& options) : directInputs_(!options.stageInputs) {
  const bool validation = options.validation && validationLayerInstalled() &&
                          instanceExtensionAvailable(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  instance_ = createInstance(validation);
  try {
    if (validation) {
      VkDebugUtilsMessengerCreateInfoEXT m{};
      m.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
      m.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
      m.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
      m.pfnUserCallback = debugCallback;
      m.pUserData = this;
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
      if (!create) throw std::runtime_error("vkGetInstanceProcAddr(vkCreateDebugUtilsMessengerEXT) returned null");
      vkCheck(create(instance_, &m, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
    }

    // ---- Device selection ------------------------------------------------
    const auto devices = physicalDevices(instance_);
    std::vector<DeviceInfo> infos;
    for (std::size_t i = 0; i < devices.size(); ++i) infos.push_back(describe(devices[i], static_cast<int>(i)));
    if (devices.empty()) throw std::runtime_error("no Vulkan device: the loader found no physical devices "
                                                  "(install mesa-vulkan-drivers for the lavapipe CPU device)");
    int chosen = -1;
    if (!options.device.empty()) {
      const bool isIndex = std::all_of(options.device.begin(), options.device.end(),
                                       [](unsigned char c) { return std::isdigit(c) != 0; });
      for (DeviceInfo& d : infos) {
        const bool match = isIndex ? std::to_string(d.index) == options.device
                                   : lower(d.name).find(lower(options.device)) != std::string::npos;
        if (!match) {
          if (d.rejected.empty()) d.rejected = "does not match --device \"" + options.device + "\"";
          continue;
        }
        if (d.rejected.empty() && chosen < 0) chosen = d.index;
      }
    } else {
      int bestRank = 1 << 20;
      for (const DeviceInfo& d : infos) {
        if (!d.rejected.empty()) continue;
        VkPhysicalDeviceProperties p{};
        vkGetPhysicalDeviceProperties(devices[static_cast<std::size_t>(d.index)], &p);
        if (typeRank(p.deviceType) < bestRank) {
          bestRank = typeRank(p.deviceType);
          chosen = d.index;
        }
      }
    }
    if (chosen < 0) {
      throw std::runtime_error(std::string("no usable Vulkan device") +
                               (options.device.empty() ? "" : " for --device \"" + options.device + "\"") +
                               "; devices:\n" + describeDevices(infos));
    }
    physical_ = devices[static_cast<std::size_t>(chosen)];
    info_ = infos[static_cast<std::size_t>(chosen)];
    vkGetPhysicalDeviceProperties(physical_, &properties_);
    VkPhysicalDeviceSubgroupProperties subgroup{};
    subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    VkPhysicalDeviceProperties2 properties2{};
    properties2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    properties2.pNext = &subgroup;
    vkGetPhysicalDeviceProperties2(physical_, &properties2);
    subgroupSize_ = std::max<std::uint32_t>(subgroup.subgroupSize, 1);
    vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
    queueFamily_ = *findQueueFamily(physical_, &timestampValidBits_);

    // ---- Device and queue ------------------------------------------------
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo q{};
    q.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    q.queueFamilyIndex = queueFamily_;
    q.queueCount = 1;
    q.pQueuePriorities = &priority;
    VkDeviceCreateInfo d{};
    d.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    d.queueCreateInfoCount = 1;
    d.pQueueCreateInfos = &q;
    vkCheck(vkCreateDevice(physical_, &d, nullptr, &device_), "vkCreateDevice");
    vkGetDeviceQueue(device_, queueFamily_, 0, &queue_);

    VkCommandPoolCreateInfo pool{};
    pool.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = queueFamily_;
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
  if (device_) {
    vkDeviceWaitIdle(device_);  // best effort: nothing to report from a destructor
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
  device_ = VK_NULL_HANDLE;
  fence_ = VK_NULL_HANDLE;
  pool_ = VK_NULL_HANDLE;
  messenger_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
}

void Context::submit(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandBufferAllocateInfo a{};
  a.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
  a.commandPool = pool_;
  a.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  a.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  vkCheck(vkAllocateCommandBuffers(device_, &a, &cb), "vkAllocateCommandBuffers");
  struct Free {
    VkDevice device;
    VkCommandPool pool;
    VkCommandBuffer cb;
    ~Free() { vkFreeCommandBuffers(device, pool, 1, &cb); }
  } guard{device_, pool_, cb};
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
  vkCheck(vkResetFences(device_, 1, &fence_), "vkResetFences");
  vkCheck(vkQueueSubmit(queue_, 1, &s, fence_), "vkQueueSubmit");
  vkCheck(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
}

std::uint32_t Context::memoryType(std::uint32_t typeBits, VkMemoryPropertyFlags required,
                                  VkMemoryPropertyFlags preferred) const {
  for (const VkMemoryPropertyFlags want : {required | preferred, required}) {
    for (std::uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
      if ((typeBits & (1u << i)) && (memory_.memoryTypes[i].propertyFlags & want) == want) return i;
    }
  }
  throw std::runtime_error("no Vulkan memory type with properties " + std::to_string(required) + " among type bits " +
                           std::to_string(typeBits) + " on " + info_.name);
}

VkDeviceMemory Context::allocate(VkDeviceSize bytes, std::uint32_t typeIndex) {
  VkMemoryAllocateInfo a{};
  a.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
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

std::vector<std::string> Context::validationMessages() const {
  std::lock_guard lock(messagesMutex_);
  return messages_;
}

void Context::clearValidationMessages() {
  std::lock_guard lock(messagesMutex_);
  messages_.clear();
}

void Context::addValidationMessage(std::string message) {
  std::lock_guard lock(messagesMutex_);
  messages_.push_back(std::move(message));
}

}  // namespace haarcast::gpu
