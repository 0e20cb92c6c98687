// Shared by the Vulkan tests: the process's engine made with validation
// before any other Vulkan use, the fixture every GPU test runs in, skipping
// only when no Vulkan device exists at all, and the check that no
// validation message was reported.
#pragma once

#include <cstdint>
#include <exception>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "haarcast/gpu/context.h"
#include "haarcast/gpu/engine.h"

namespace haarcast::gpu::testing {

// The engine of the test binary (engine.h): one instance for every test,
// made here first, with validation on whenever the layer is installed (a
// vulkanAvailable() or a Context asking for none would make it without).
// Null when no Vulkan instance can be created.
inline Engine* testEngine() {
  static Engine* const engine = []() -> Engine* {
    try {
      return &Engine::get(EngineOptions{true});
    } catch (const std::exception&) {
      return nullptr;
    }
  }();
  return engine;
}

inline bool haveVulkan() {
  static const bool available = testEngine() != nullptr && !testEngine()->devices().empty();
  return available;
}

inline VulkanOptions testOptions() {
  VulkanOptions o;
  o.validation = true;  // on whenever the layer is installed
  o.queues = 0;         // every queue the device offers: the tests run on several where it has them
  return o;
}

// Every validation warning or error fails the test that caused it.
inline void expectNoValidationMessages(const Context& context) {
  for (const std::string& m : context.validationMessages()) ADD_FAILURE() << "validation: " << m;
}

// The fixture of the GPU tests: the engine made first (so that validation
// is on), and every validation message from the test's start to its end
// fails it, whichever Context caused it and even where the test checks none
// (a destructor's, a message between two Contexts). The per-Context
// expectNoValidationMessages says which step caused it.
template <class Base>
class WithEngine : public Base {
 protected:
  void SetUp() override {
    Base::SetUp();
    if (Engine* engine = testEngine()) mark_ = engine->validationLog().count();
  }
  void TearDown() override {
    if (Engine* engine = testEngine()) {
      for (const std::string& m : engine->validationLog().since(mark_)) ADD_FAILURE() << "validation during the test: " << m;
    }
    Base::TearDown();
  }

 private:
  std::uint64_t mark_ = 0;
};
using GpuTest = WithEngine<::testing::Test>;
template <class T>
using GpuTestWithParam = WithEngine<::testing::TestWithParam<T>>;

}  // namespace haarcast::gpu::testing

// TEST with the GpuTest fixture, under the suite's own name (TEST_F would
// need a fixture class named as the suite, and several suites are named
// after the classes they test, VulkanRenderer among them). GTEST_TEST_ is
// what TEST itself expands to, with ::testing::Test as the parent.
#define GPU_TEST(suite, name)                                \
  GTEST_TEST_(suite, name, ::haarcast::gpu::testing::GpuTest, \
              ::testing::internal::GetTypeId<::haarcast::gpu::testing::GpuTest>())

#define HAARCAST_REQUIRE_VULKAN()                                              \
  do {                                                                         \
    if (!::haarcast::gpu::testing::haveVulkan()) GTEST_SKIP() << "no Vulkan device"; \
  } while (0)
