#include "haarcast/gpu/compute.h"

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <string>

#include "haarcast/gpu/shaders.h"

namespace haarcast::gpu {

VkShaderModule createShaderModule(Context& context, std::string_view name) {
  const std::span<const std::uint32_t> words = embeddedShader(name);
  if (words.empty()) {
    std::string known;
    for (const std::string_view n : embeddedShaderNames()) known += (known.empty() ? "" : ", ") + std::string(n);
    throw std::invalid_argument("no embedded shader \"" + std::string(name) + "\" (embedded: " + known + ")");
  }
  VkShaderModuleCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
  info.codeSize = words.size_bytes();
  info.pCode = words.data();
  VkShaderModule module = VK_NULL_HANDLE;
  vkCheck(vkCreateShaderModule(context.device(), &info, nullptr, &module), "vkCreateShaderModule");
  return module;
}

namespace {
VkDescriptorType descriptorType(BindingKind kind) {
  return kind == BindingKind::Texels ? VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
}
}  // namespace

ComputePipeline::ComputePipeline(Context& context, std::string_view shaderName, std::uint32_t storageBuffers,
                                 std::uint32_t pushConstantBytes, std::vector<SpecConstant> specialization)
    : ComputePipeline(context, shaderName, std::vector<BindingKind>(storageBuffers, BindingKind::Storage),
                      pushConstantBytes, std::move(specialization)) {}

ComputePipeline::ComputePipeline(Context& context, std::string_view shaderName, std::vector<BindingKind> bindings,
                                 std::uint32_t pushConstantBytes, std::vector<SpecConstant> specialization)
    : context_(context), name_(shaderName), bindings_(std::move(bindings)), pushBytes_(pushConstantBytes) {
  VkDevice device = context.device();
  VkShaderModule module = createShaderModule(context, shaderName);
  try {
    setLayout_ = createSetLayout(device, bindings_, VK_SHADER_STAGE_COMPUTE_BIT);

    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, pushConstantBytes};
    VkPipelineLayoutCreateInfo pl{};
    pl.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &setLayout_;
    pl.pushConstantRangeCount = pushConstantBytes ? 1 : 0;
    pl.pPushConstantRanges = &range;
    vkCheck(vkCreatePipelineLayout(device, &pl, nullptr, &layout_), "vkCreatePipelineLayout");

    std::vector<VkSpecializationMapEntry> entries;
    std::vector<std::uint32_t> values;
    for (const SpecConstant& c : specialization) {
      entries.push_back({c.id, static_cast<std::uint32_t>(values.size() * sizeof(std::uint32_t)), sizeof(std::uint32_t)});
      values.push_back(c.value);
    }
    VkSpecializationInfo spec{};
    spec.mapEntryCount = static_cast<std::uint32_t>(entries.size());
    spec.pMapEntries = entries.data();
    spec.dataSize = values.size() * sizeof(std::uint32_t);
    spec.pData = values.data();

    VkComputePipelineCreateInfo cp{};
    cp.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    cp.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    cp.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cp.stage.module = module;
    cp.stage.pName = "main";
    cp.stage.pSpecializationInfo = entries.empty() ? nullptr : &spec;
    cp.layout = layout_;
    vkCheck(vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &cp, nullptr, &pipeline_), "vkCreateComputePipelines");

    allocateSet(device, setLayout_, bindings_, pool_, set_);
  } catch (...) {
    vkDestroyShaderModule(device, module, nullptr);
    destroy();  // the destructor does not run for a constructor that throws
    throw;
  }
  vkDestroyShaderModule(device, module, nullptr);
}

ComputePipeline::~ComputePipeline() { destroy(); }

void ComputePipeline::destroy() {
  VkDevice device = context_.device();
  if (pool_) vkDestroyDescriptorPool(device, pool_, nullptr);
  if (pipeline_) vkDestroyPipeline(device, pipeline_, nullptr);
  if (layout_) vkDestroyPipelineLayout(device, layout_, nullptr);
  if (setLayout_) vkDestroyDescriptorSetLayout(device, setLayout_, nullptr);
  pool_ = VK_NULL_HANDLE;
  pipeline_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  setLayout_ = VK_NULL_HANDLE;
}

void ComputePipeline::bind(std::initializer_list<Bound> resources) {
  if (resources.size() != bindings_.size()) {
    throw std::invalid_argument(name_ + ": bind() got " + std::to_string(resources.size()) + " resources for " +
                                std::to_string(bindings_.size()) + " bindings");
  }
  std::vector<const Bound*> at;
  for (const Bound& r : resources) at.push_back(&r);
  bindAll(at);
}

void ComputePipeline::bind(std::initializer_list<BindingAt> resources) {
  std::vector<const Bound*> at(bindings_.size(), nullptr);
  for (const BindingAt& r : resources) {
    if (r.binding >= at.size() || at[r.binding]) {
      throw std::invalid_argument(name_ + ": bind() got binding " + std::to_string(r.binding) +
                                  (r.binding >= at.size() ? " of " + std::to_string(at.size()) : " twice"));
    }
    at[r.binding] = &r.resource;
  }
  for (std::size_t i = 0; i < at.size(); ++i) {
    if (!at[i]) throw std::invalid_argument(name_ + ": bind() got nothing for binding " + std::to_string(i));
  }
  bindAll(at);
}

void ComputePipeline::bindAll(const std::vector<const Bound*>& resources) {
  std::vector<VkDescriptorBufferInfo> infos(resources.size());
  std::vector<VkBufferView> views(resources.size());
  std::vector<VkWriteDescriptorSet> writes(resources.size());
  for (std::size_t i = 0; i < resources.size(); ++i) {
    const Bound& r = *resources[i];
    const BindingKind kind = bindings_[i];
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = set_;
    writes[i].dstBinding = static_cast<std::uint32_t>(i);
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = descriptorType(kind);
    if (kind == BindingKind::Texels) {
      if (!r.texels || !r.texels->handle()) {
        throw std::invalid_argument(name_ + ": binding " + std::to_string(i) + " takes a texel view");
      }
      views[i] = r.texels->handle();
      writes[i].pTexelBufferView = &views[i];
    } else {
      if (!r.buffer || !r.buffer->handle()) {
        throw std::invalid_argument(name_ + ": binding " + std::to_string(i) + " takes a buffer");
      }
      infos[i] = {r.buffer->handle(), 0, VK_WHOLE_SIZE};
      writes[i].pBufferInfo = &infos[i];
    }
  }
  vkUpdateDescriptorSets(context_.device(), static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
}

void ComputePipeline::dispatch(VkCommandBuffer cb, std::array<std::uint32_t, 3> groups, const void* push,
                               std::uint32_t pushBytes) const {
  bindForDispatch(cb, push, pushBytes);
  if (groups[0] && groups[1] && groups[2]) vkCmdDispatch(cb, groups[0], groups[1], groups[2]);
}

void ComputePipeline::dispatchIndirect(VkCommandBuffer cb, const Buffer& args, VkDeviceSize offset, const void* push,
                                       std::uint32_t pushBytes) const {
  bindForDispatch(cb, push, pushBytes);
  vkCmdDispatchIndirect(cb, args.handle(), offset);
}

void ComputePipeline::bindForDispatch(VkCommandBuffer cb, const void* push, std::uint32_t pushBytes) const {
  if (pushBytes != pushBytes_) {
    throw std::invalid_argument(name_ + ": push constants of " + std::to_string(pushBytes) + " bytes, expected " +
                                std::to_string(pushBytes_));
  }
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set_, 0, nullptr);
  if (pushBytes) vkCmdPushConstants(cb, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushBytes, push);
}

void computeBarrier(VkCommandBuffer cb) {
  VkMemoryBarrier m{};
  m.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  m.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  m.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                    VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT |
                           VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                       0, 1, &m, 0, nullptr, 0, nullptr);
}

VkDescriptorSetLayout createSetLayout(VkDevice device, const std::vector<BindingKind>& kinds, VkShaderStageFlags stages) {
  std::vector<VkDescriptorSetLayoutBinding> bindings(kinds.size());
  for (std::size_t i = 0; i < kinds.size(); ++i) {
    bindings[i].binding = static_cast<std::uint32_t>(i);
    bindings[i].descriptorType = descriptorType(kinds[i]);
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = stages;
  }
  VkDescriptorSetLayoutCreateInfo sl{};
  sl.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  sl.bindingCount = static_cast<std::uint32_t>(bindings.size());
  sl.pBindings = bindings.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  vkCheck(vkCreateDescriptorSetLayout(device, &sl, nullptr, &layout), "vkCreateDescriptorSetLayout");
  return layout;
}

VkDescriptorSetLayout createStorageSetLayout(VkDevice device, std::uint32_t storageBuffers, VkShaderStageFlags stages) {
  return createSetLayout(device, std::vector<BindingKind>(storageBuffers, BindingKind::Storage), stages);
}

void allocateSet(VkDevice device, VkDescriptorSetLayout layout, const std::vector<BindingKind>& kinds,
                 VkDescriptorPool& pool, VkDescriptorSet& set) {
  std::vector<VkDescriptorPoolSize> sizes;
  for (const BindingKind kind : {BindingKind::Storage, BindingKind::Texels}) {
    const auto count = static_cast<std::uint32_t>(std::count(kinds.begin(), kinds.end(), kind));
    if (count) sizes.push_back({descriptorType(kind), count});
  }
  if (sizes.empty()) sizes.push_back({VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1});
  VkDescriptorPoolCreateInfo dp{};
  dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dp.maxSets = 1;
  dp.poolSizeCount = static_cast<std::uint32_t>(sizes.size());
  dp.pPoolSizes = sizes.data();
  vkCheck(vkCreateDescriptorPool(device, &dp, nullptr, &pool), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo da{};
  da.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  da.descriptorPool = pool;
  da.descriptorSetCount = 1;
  da.pSetLayouts = &layout;
  vkCheck(vkAllocateDescriptorSets(device, &da, &set), "vkAllocateDescriptorSets");
}

void allocateStorageSet(VkDevice device, VkDescriptorSetLayout layout, std::uint32_t storageBuffers,
                        VkDescriptorPool& pool, VkDescriptorSet& set) {
  allocateSet(device, layout, std::vector<BindingKind>(storageBuffers, BindingKind::Storage), pool, set);
}

}  // namespace haarcast::gpu
