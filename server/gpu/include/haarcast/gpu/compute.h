// A compute pipeline built from an embedded shader (shaders.h): storage
// buffers or uniform texel buffers at set 0, bindings 0 … n−1, an optional
// push-constant block, and 32-bit specialization constants (sizes such as
// the map level).
#pragma once

#include <array>
#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <vulkan/vulkan.h>

#include "haarcast/gpu/buffer.h"
#include "haarcast/gpu/context.h"

namespace haarcast::gpu {

struct SpecConstant {
  std::uint32_t id = 0;     // constant_id in the shader
  std::uint32_t value = 0;  // int/uint value (or a float's bits)
};

// What one binding of set 0 holds.
enum class BindingKind {
  Storage,  // a storage buffer (a std430 block)
  // A uniform texel buffer (samplerBuffer, texelFetch) through a TexelView.
  // On a CPU device (lavapipe) a texel fetch is a vector gather, while a
  // storage-buffer read at a per-invocation index runs lane by lane and
  // component by component, each behind a branch: large read-only arrays
  // read in a hot loop belong here.
  Texels,
};

// One resource to bind: a storage buffer or a texel view.
struct Bound {
  Bound(const Buffer* b) : buffer(b) {}      // NOLINT: implicit, so that bind({&a, &b}) reads naturally
  Bound(const TexelView* t) : texels(t) {}   // NOLINT
  const Buffer* buffer = nullptr;
  const TexelView* texels = nullptr;
};

// A resource for one binding of set 0, named by the pass's binding constant
// (core/shared_passes.h), the number the shader declares it at.
struct BindingAt {
  std::uint32_t binding = 0;
  Bound resource;
};

// A VkShaderModule from the embedded SPIR-V of shaders/<name>; throws
// std::invalid_argument naming the shader when it is not embedded.
VkShaderModule createShaderModule(Context& context, std::string_view name);

class ComputePipeline {
 public:
  // storageBuffers: bindings 0 … storageBuffers−1 of set 0, each a storage
  // buffer. pushConstantBytes: 0 or the size of the shader's push block.
  ComputePipeline(Context& context, std::string_view shaderName, std::uint32_t storageBuffers,
                  std::uint32_t pushConstantBytes, std::vector<SpecConstant> specialization = {});
  // bindings: what binding i holds, for i = 0 … bindings.size() − 1.
  ComputePipeline(Context& context, std::string_view shaderName, std::vector<BindingKind> bindings,
                  std::uint32_t pushConstantBytes, std::vector<SpecConstant> specialization = {});
  ~ComputePipeline();
  ComputePipeline(const ComputePipeline&) = delete;
  ComputePipeline& operator=(const ComputePipeline&) = delete;

  // Points binding i at resources[i] (a whole buffer, or a texel view for a
  // Texels binding). Must not be called while a submitted command buffer
  // that uses this pipeline is still running (Context::submit waits, so
  // between submits is fine).
  void bind(std::initializer_list<Bound> resources);
  // The same by binding number: every binding once, in any order.
  void bind(std::initializer_list<BindingAt> resources);
  // Binds the pipeline and its descriptor set, pushes `push` and dispatches.
  void dispatch(VkCommandBuffer cb, std::array<std::uint32_t, 3> groups, const void* push = nullptr,
                std::uint32_t pushBytes = 0) const;

  // The same with the group counts read on the device from `args` at
  // `offset` (a VkDispatchIndirectCommand; the buffer needs INDIRECT usage).
  void dispatchIndirect(VkCommandBuffer cb, const Buffer& args, VkDeviceSize offset, const void* push = nullptr,
                        std::uint32_t pushBytes = 0) const;

  const std::string& name() const { return name_; }

 private:
  void destroy();
  // resources[i] for binding i, every binding's.
  void bindAll(const std::vector<const Bound*>& resources);
  void bindForDispatch(VkCommandBuffer cb, const void* push, std::uint32_t pushBytes) const;
  Context& context_;
  std::string name_;
  std::vector<BindingKind> bindings_;
  std::uint32_t pushBytes_ = 0;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
};

// Compute and transfer writes visible to later compute reads, indirect
// dispatch arguments, transfers and the host (the barrier between two
// passes of one command buffer).
void computeBarrier(VkCommandBuffer cb);

// A set layout with binding i of kind bindings[i], visible to `stages`. The
// caller destroys it.
VkDescriptorSetLayout createSetLayout(VkDevice device, const std::vector<BindingKind>& bindings,
                                      VkShaderStageFlags stages);
// The same for `storageBuffers` storage buffers.
VkDescriptorSetLayout createStorageSetLayout(VkDevice device, std::uint32_t storageBuffers, VkShaderStageFlags stages);

// One descriptor set for `bindings` with `layout`, from a pool of its own
// (sized for exactly that set). The caller destroys the pool.
void allocateSet(VkDevice device, VkDescriptorSetLayout layout, const std::vector<BindingKind>& bindings,
                 VkDescriptorPool& pool, VkDescriptorSet& set);
// The same for `storageBuffers` storage buffers.
void allocateStorageSet(VkDevice device, VkDescriptorSetLayout layout, std::uint32_t storageBuffers,
                        VkDescriptorPool& pool, VkDescriptorSet& set);

}  // namespace haarcast::gpu
