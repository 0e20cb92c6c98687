#include "haarcast/gpu/compute.h"

#include <stdexcept>
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

ComputePipeline::ComputePipeline(Context& context, std::string_view shaderName, std::uint32_t storageBuffers,
                                 std::uint32_t pushConstantBytes, std::vector<SpecConstant> specialization)
    : context_(context), name_(shaderName), bindings_(storageBuffers), pushBytes_(pushConstantBytes) {
  VkDevice device = context.device();
  VkShaderModule module = createShaderModule(context, shaderName);
  try {
    setLayout_ = createStorageSetLayout(device, storageBuffers, VK_SHADER_STAGE_COMPUTE_BIT);

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

    allocateStorageSet(device, setLayout_, storageBuffers, pool_, set_);
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

void ComputePipeline::bind(std::initializer_list<const Buffer*> buffers) {
  if (buffers.size() != bindings_) {
    throw std::invalid_argument(name_ + ": bind() got " + std::to_string(buffers.size()) + " buffers for " +
                                std::to_string(bindings_) + " bindings");
  }
  std::vector<VkDescriptorBufferInfo> infos;
  for (const Buffer* b : buffers) {
    if (!b || !b->handle()) throw std::invalid_argument(name_ + ": bind() got an empty buffer");
    infos.push_back({b->handle(), 0, VK_WHOLE_SIZE});
  }
  std::vector<VkWriteDescriptorSet> writes(infos.size());
  for (std::size_t i = 0; i < infos.size(); ++i) {
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = set_;
    writes[i].dstBinding = static_cast<std::uint32_t>(i);
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
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

VkDescriptorSetLayout createStorageSetLayout(VkDevice device, std::uint32_t storageBuffers, VkShaderStageFlags stages) {
  std::vector<VkDescriptorSetLayoutBinding> bindings(storageBuffers);
  for (std::uint32_t i = 0; i < storageBuffers; ++i) {
    bindings[i].binding = i;
    bindings[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[i].descriptorCount = 1;
    bindings[i].stageFlags = stages;
  }
  VkDescriptorSetLayoutCreateInfo sl{};
  sl.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
  sl.bindingCount = storageBuffers;
  sl.pBindings = bindings.data();
  VkDescriptorSetLayout layout = VK_NULL_HANDLE;
  vkCheck(vkCreateDescriptorSetLayout(device, &sl, nullptr, &layout), "vkCreateDescriptorSetLayout");
  return layout;
}

void allocateStorageSet(VkDevice device, VkDescriptorSetLayout layout, std::uint32_t storageBuffers,
                        VkDescriptorPool& pool, VkDescriptorSet& set) {
  VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, std::max<std::uint32_t>(storageBuffers, 1)};
  VkDescriptorPoolCreateInfo dp{};
  dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
  dp.maxSets = 1;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &size;
  vkCheck(vkCreateDescriptorPool(device, &dp, nullptr, &pool), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo da{};
  da.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
  da.descriptorPool = pool;
  da.descriptorSetCount = 1;
  da.pSetLayouts = &layout;
  vkCheck(vkAllocateDescriptorSets(device, &da, &set), "vkAllocateDescriptorSets");
}

}  // namespace haarcast::gpu
