// Shared by the Vulkan tests: skip only when no Vulkan device exists at all,
// validation on, and a check that no validation message was reported.
#pragma once

#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "haarcast/gpu/context.h"

namespace haarcast::gpu::testing {

inline bool haveVulkan() {
  static const bool available = vulkanAvailable();
  return available;
}

inline VulkanOptions testOptions() {
  VulkanOptions o;
  o.validation = true;  // on whenever the layer is installed
  return o;
}

// Every validation warning or error fails the test that caused it.
inline void expectNoValidationMessages(const Context& context) {
  for (const std::string& m : context.validationMessages()) ADD_FAILURE() << "validation: " << m;
}

}  // namespace haarcast::gpu::testing

#define HAARCAST_REQUIRE_VULKAN()                                              \
  do {                                                                         \
    if (!::haarcast::gpu::testing::haveVulkan()) GTEST_SKIP() << "no Vulkan device"; \
  } while (0)
