// The process's Vulkan engine (engine.h): the instance, the physical devices
// listed once, device selection, one VkDevice per physical device, and the
// device queries that need no device (vulkanAvailable, listDevices).
#include "haarcast/gpu/engine.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include "haarcast/core/check.h"

namespace haarcast::gpu {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr std::uint32_t kRequiredApi = VK_API_VERSION_1_2;

// Constant-initialised, so that they exist before and after every static
// that could count.
std::atomic<std::uint64_t> gInstancesCreated{0};
std::atomic<std::uint64_t> gDevicesCreated{0};

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

// HAARCAST_VULKAN_VALIDATION=1 (any value but "0" or empty) turns validation
// on for the process whatever the first request asked.
bool validationFromEnvironment() {
  const char* v = std::getenv("HAARCAST_VULKAN_VALIDATION");
  return v && *v && std::strcmp(v, "0") != 0;
}

// A queue family with graphics and compute (the G-buffer and the passes
// share each queue), or nothing; `queueCount`: how many queues it has.
std::optional<std::uint32_t> findQueueFamily(VkPhysicalDevice device, std::uint32_t* timestampBits = nullptr,
                                             std::uint32_t* queueCount = nullptr) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  for (std::uint32_t i = 0; i < count; ++i) {
    const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    if ((families[i].queueFlags & need) == need) {
      if (timestampBits) *timestampBits = families[i].timestampValidBits;
      if (queueCount) *queueCount = families[i].queueCount;
      return i;
    }
  }
  return std::nullopt;
}

// The queues a device is opened with: its family's, at most `limit`
// (0 = kMaxDeviceQueues), at least one.
std::uint32_t queuesToOpen(VkPhysicalDevice device, std::uint32_t limit) {
  std::uint32_t offered = 1;
  findQueueFamily(device, nullptr, &offered);
  return std::clamp(offered, 1u, limit == 0 ? kMaxDeviceQueues : limit);
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

bool deviceExtensionAvailable(VkPhysicalDevice device, const char* name) {
  std::uint32_t count = 0;
  if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkExtensionProperties> exts(count);
  if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, exts.data()) != VK_SUCCESS) return false;
  return std::any_of(exts.begin(), exts.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

// The extensions ray tracing needs (RayTracingSupport), checked and enabled alike.
constexpr std::array<const char*, 3> kRayExtensions = {VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME,
                                                       VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME,
                                                       VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME};

RayTracingSupport rayTracingSupport(VkPhysicalDevice device) {
  RayTracingSupport support;
  std::string missing;
  for (const char* name : kRayExtensions) {
    if (!deviceExtensionAvailable(device, name)) missing += std::string(missing.empty() ? "" : ", ") + name;
  }
  if (missing.empty()) {
    VkPhysicalDeviceVulkan12Features v12{};
    v12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
    VkPhysicalDeviceAccelerationStructureFeaturesKHR as{};
    as.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR rt{};
    rt.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR;
    v12.pNext = &as;
    as.pNext = &rt;
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.pNext = &v12;
    vkGetPhysicalDeviceFeatures2(device, &features);
    if (!v12.bufferDeviceAddress) missing = "bufferDeviceAddress";
    if (!as.accelerationStructure) missing += std::string(missing.empty() ? "" : ", ") + "accelerationStructure";
    if (!rt.rayTracingPipeline) missing += std::string(missing.empty() ? "" : ", ") + "rayTracingPipeline";
  }
  if (!missing.empty()) {
    support.missing = "no " + missing;
    return support;
  }
  VkPhysicalDeviceRayTracingPipelinePropertiesKHR rt{};
  rt.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_PROPERTIES_KHR;
  VkPhysicalDeviceAccelerationStructurePropertiesKHR as{};
  as.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR;
  rt.pNext = &as;
  VkPhysicalDeviceProperties2 properties{};
  properties.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  properties.pNext = &rt;
  vkGetPhysicalDeviceProperties2(device, &properties);
  support.supported = true;
  support.handleSize = rt.shaderGroupHandleSize;
  support.handleAlignment = std::max<std::uint32_t>(rt.shaderGroupHandleAlignment, 1);
  support.baseAlignment = std::max<std::uint32_t>(rt.shaderGroupBaseAlignment, 1);
  support.scratchAlignment = std::max<std::uint32_t>(as.minAccelerationStructureScratchOffsetAlignment, 1);
  return support;
}

VKAPI_ATTR VkBool32 VKAPI_CALL debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT && data && data->pMessage) {
    static_cast<ValidationLog*>(user)->add(data->pMessage);
  }
  return VK_FALSE;  // never abort the call: the test reports the message
}

}  // namespace

// ------------------------------------------------------------------ ValidationLog

void ValidationLog::add(std::string message) {
  std::lock_guard lock(mutex_);
  kept_.push_back(std::move(message));
  if (kept_.size() > kKept) kept_.pop_front();
  ++count_;
}

std::uint64_t ValidationLog::count() const {
  std::lock_guard lock(mutex_);
  return count_;
}

std::vector<std::string> ValidationLog::since(std::uint64_t mark) const {
  std::lock_guard lock(mutex_);
  const std::uint64_t first = count_ - kept_.size();  // the number of kept_.front()
  const std::uint64_t from = std::max(mark, first);
  if (from >= count_) return {};
  return {kept_.begin() + static_cast<std::ptrdiff_t>(from - first), kept_.end()};
}

// ------------------------------------------------------------------ VulkanInstance

class VulkanInstance {
 public:
  explicit VulkanInstance(bool validationRequested) {
    const bool validation = validationRequested && layerInstalled(kValidationLayer) &&
                            instanceExtensionAvailable(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
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
    vkCheck(vkCreateInstance(&info, nullptr, &instance_), "vkCreateInstance");
    ++gInstancesCreated;
    if (!validation) return;
    try {
      VkDebugUtilsMessengerCreateInfoEXT m{};
      m.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
      m.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
      m.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
      m.pfnUserCallback = debugCallback;
      m.pUserData = &log_;
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
      if (!create) throw std::runtime_error("vkGetInstanceProcAddr(vkCreateDebugUtilsMessengerEXT) returned null");
      vkCheck(create(instance_, &m, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
    } catch (...) {
      vkDestroyInstance(instance_, nullptr);  // the destructor does not run for a constructor that throws
      throw;
    }
  }

  ~VulkanInstance() {
    if (messenger_) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
      if (destroy) destroy(instance_, messenger_, nullptr);
    }
    vkDestroyInstance(instance_, nullptr);
  }
  VulkanInstance(const VulkanInstance&) = delete;
  VulkanInstance& operator=(const VulkanInstance&) = delete;

  VkInstance handle() const { return instance_; }
  bool validationEnabled() const { return messenger_ != VK_NULL_HANDLE; }
  ValidationLog& log() { return log_; }

 private:
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  ValidationLog log_;  // the messenger's user data: lives as long as it
};

// ------------------------------------------------------------------ SharedDevice

SharedDevice::SharedDevice(std::shared_ptr<VulkanInstance> instance, VkPhysicalDevice physical, DeviceInfo info,
                           std::uint32_t queues)
    : instance_(std::move(instance)),
      physical_(physical),
      info_(std::move(info)),
      queues_(queuesToOpen(physical, queues), VK_NULL_HANDLE),
      queueMutexes_(std::make_unique<std::mutex[]>(queues_.size())),
      lender_(queues_.size()) {
  HC_CHECK_EQ(info_.rejected, "");  // Engine::device opens usable devices only
  vkGetPhysicalDeviceProperties(physical_, &properties_);
  VkPhysicalDeviceSubgroupProperties subgroup{};
  subgroup.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
  VkPhysicalDeviceProperties2 properties2{};
  properties2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
  properties2.pNext = &subgroup;
  vkGetPhysicalDeviceProperties2(physical_, &properties2);
  subgroupSize_ = std::max<std::uint32_t>(subgroup.subgroupSize, 1);
  subgroupArithmetic_ = (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT) != 0 &&
                        (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) != 0;
  subgroupBallotShuffle_ = subgroupArithmetic_ && (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_BALLOT_BIT) != 0 &&
                           (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_SHUFFLE_BIT) != 0;
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);
  queueFamily_ = *findQueueFamily(physical_, &timestampValidBits_);  // describe() found one

  // Ray tracing where the device offers all of it (context.h,
  // RayTracingSupport); the rest of the renderer needs none of it.
  rayTracing_ = rayTracingSupport(physical_);
  VkPhysicalDeviceVulkan12Features v12{};
  v12.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES;
  VkPhysicalDeviceAccelerationStructureFeaturesKHR asFeatures{};
  asFeatures.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR;
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rtFeatures{};
  rtFeatures.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR;
  if (rayTracing_.supported) {
    v12.bufferDeviceAddress = VK_TRUE;
    asFeatures.accelerationStructure = VK_TRUE;
    rtFeatures.rayTracingPipeline = VK_TRUE;
    v12.pNext = &asFeatures;
    asFeatures.pNext = &rtFeatures;
  }

  // Every queue the same priority: the sessions' frames are equals.
  const std::vector<float> priorities(queues_.size(), 1.0f);
  VkDeviceQueueCreateInfo q{};
  q.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
  q.queueFamilyIndex = queueFamily_;
  q.queueCount = static_cast<std::uint32_t>(queues_.size());
  q.pQueuePriorities = priorities.data();
  VkDeviceCreateInfo d{};
  d.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
  d.queueCreateInfoCount = 1;
  d.pQueueCreateInfos = &q;
  if (rayTracing_.supported) {
    d.pNext = &v12;
    d.enabledExtensionCount = static_cast<std::uint32_t>(kRayExtensions.size());
    d.ppEnabledExtensionNames = kRayExtensions.data();
  }
  vkCheck(vkCreateDevice(physical_, &d, nullptr, &device_), "vkCreateDevice");
  ++gDevicesCreated;
  for (std::uint32_t i = 0; i < queues_.size(); ++i) vkGetDeviceQueue(device_, queueFamily_, i, &queues_[i]);
}

SharedDevice::~SharedDevice() {
  // Every Context on this device is gone (each held it), and each waited for
  // its own submissions; nothing is in flight.
  vkDestroyDevice(device_, nullptr);
}

VkInstance SharedDevice::instance() const { return instance_->handle(); }
bool SharedDevice::validationEnabled() const { return instance_->validationEnabled(); }
ValidationLog& SharedDevice::validationLog() const { return instance_->log(); }

void SharedDevice::submit(std::uint32_t index, const VkSubmitInfo& submit, VkFence fence) {
  HC_CHECK_LT(index, queues_.size());
  std::lock_guard lock(queueMutexes_[index]);
  vkCheck(vkQueueSubmit(queues_[index], 1, &submit, fence), "vkQueueSubmit");
}

// ------------------------------------------------------------------ Engine

Engine& Engine::get(const EngineOptions& options) {
  // A function-local static: made on the first call, thread-safe, made
  // again on the next call if the first threw; destroyed at exit before
  // the loader is unloaded (engine.h).
  static Engine engine(options);
  return engine;
}

Engine::Engine(const EngineOptions& options)
    : instance_(std::make_shared<VulkanInstance>(options.validation || validationFromEnvironment())) {
  physical_ = physicalDevices(instance_->handle());
  for (std::size_t i = 0; i < physical_.size(); ++i) infos_.push_back(describe(physical_[i], static_cast<int>(i)));
  opened_.resize(physical_.size());
}

Engine::~Engine() = default;

VkInstance Engine::instance() const { return instance_->handle(); }
bool Engine::validationEnabled() const { return instance_->validationEnabled(); }
ValidationLog& Engine::validationLog() const { return instance_->log(); }
std::uint64_t Engine::instancesCreated() { return gInstancesCreated.load(); }
std::uint64_t Engine::devicesCreated() { return gDevicesCreated.load(); }

std::shared_ptr<SharedDevice> Engine::device(const std::string& selector, std::uint32_t queues) {
  if (physical_.empty()) {
    throw std::runtime_error("no Vulkan device: the loader found no physical devices "
                             "(install mesa-vulkan-drivers for the lavapipe CPU device)");
  }
  std::vector<DeviceInfo> infos = infos_;  // this selection's reasons added to a copy
  int chosen = -1;
  if (!selector.empty()) {
    const bool isIndex =
        std::all_of(selector.begin(), selector.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
    for (DeviceInfo& d : infos) {
      const bool match = isIndex ? std::to_string(d.index) == selector
                                 : lower(d.name).find(lower(selector)) != std::string::npos;
      if (!match) {
        if (d.rejected.empty()) d.rejected = "does not match --device \"" + selector + "\"";
        continue;
      }
      if (d.rejected.empty() && chosen < 0) chosen = d.index;
    }
  } else {
    int bestRank = 1 << 20;
    for (const DeviceInfo& d : infos) {
      if (!d.rejected.empty()) continue;
      VkPhysicalDeviceProperties p{};
      vkGetPhysicalDeviceProperties(physical_[static_cast<std::size_t>(d.index)], &p);
      if (typeRank(p.deviceType) < bestRank) {
        bestRank = typeRank(p.deviceType);
        chosen = d.index;
      }
    }
  }
  if (chosen < 0) {
    throw std::runtime_error(std::string("no usable Vulkan device") +
                             (selector.empty() ? "" : " for --device \"" + selector + "\"") + "; devices:\n" +
                             describeDevices(infos));
  }
  const auto at = static_cast<std::size_t>(chosen);
  std::lock_guard lock(devicesMutex_);
  if (!opened_[at]) opened_[at] = std::make_shared<SharedDevice>(instance_, physical_[at], infos_[at], queues);
  return opened_[at];
}

// ------------------------------------------------------------------ queries

bool validationLayerInstalled() { return layerInstalled(kValidationLayer); }

bool vulkanAvailable() {
  try {
    return !Engine::get().devices().empty();
  } catch (const std::exception&) {
    return false;
  }
}

std::vector<DeviceInfo> listDevices() { return Engine::get().devices(); }

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

}  // namespace haarcast::gpu
