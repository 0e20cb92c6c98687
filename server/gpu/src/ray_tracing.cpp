// Acceleration structures and the ray-tracing pipeline (ray_tracing.h).
#include "haarcast/gpu/ray_tracing.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>

#include "haarcast/core/check.h"
#include "haarcast/core/shared_layout.h"

namespace haarcast::gpu {
namespace {

void requireRayTracing(const Context& context, const char* what) {
  if (!context.rayTracing().supported) {
    throw std::runtime_error(std::string(what) + " needs ray tracing, which " + context.info().name + " lacks (" +
                             context.rayTracing().missing + ")");
  }
}

template <class F>
F load(VkDevice device, const char* name) {
  auto f = reinterpret_cast<F>(vkGetDeviceProcAddr(device, name));
  if (!f) throw std::runtime_error(std::string("vkGetDeviceProcAddr(") + name + ") returned null");
  return f;
}

VkDeviceSize alignUp(VkDeviceSize value, VkDeviceSize alignment) { return (value + alignment - 1) / alignment * alignment; }

constexpr VkBufferUsageFlags kAddressed = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
constexpr VkBufferUsageFlags kBuildInput =
    kAddressed | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// A build of one geometry into a structure of `type`, traced more than
// built (the bottom levels once, the top level every frame, both traced by
// every sample's rays).
VkAccelerationStructureBuildGeometryInfoKHR buildOf(VkAccelerationStructureTypeKHR type,
                                                    const VkAccelerationStructureGeometryKHR* geometry) {
  VkAccelerationStructureBuildGeometryInfoKHR b{};
  b.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR;
  b.type = type;
  b.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  b.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  b.geometryCount = 1;
  b.pGeometries = geometry;
  return b;
}

}  // namespace

RayFunctions::RayFunctions(VkDevice device)
    : createAccelerationStructure(load<PFN_vkCreateAccelerationStructureKHR>(device, "vkCreateAccelerationStructureKHR")),
      destroyAccelerationStructure(load<PFN_vkDestroyAccelerationStructureKHR>(device, "vkDestroyAccelerationStructureKHR")),
      getBuildSizes(load<PFN_vkGetAccelerationStructureBuildSizesKHR>(device, "vkGetAccelerationStructureBuildSizesKHR")),
      cmdBuild(load<PFN_vkCmdBuildAccelerationStructuresKHR>(device, "vkCmdBuildAccelerationStructuresKHR")),
      getDeviceAddress(load<PFN_vkGetAccelerationStructureDeviceAddressKHR>(device, "vkGetAccelerationStructureDeviceAddressKHR")),
      createPipelines(load<PFN_vkCreateRayTracingPipelinesKHR>(device, "vkCreateRayTracingPipelinesKHR")),
      getGroupHandles(load<PFN_vkGetRayTracingShaderGroupHandlesKHR>(device, "vkGetRayTracingShaderGroupHandlesKHR")),
      cmdTraceRays(load<PFN_vkCmdTraceRaysKHR>(device, "vkCmdTraceRaysKHR")) {}

void rayTracingBarrier(VkCommandBuffer cb) {
  constexpr VkPipelineStageFlags kStages = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT |
                                           VK_PIPELINE_STAGE_RAY_TRACING_SHADER_BIT_KHR |
                                           VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR;
  VkMemoryBarrier m{};
  m.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  m.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  m.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                    VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR |
                    VK_ACCESS_INDIRECT_COMMAND_READ_BIT;
  vkCmdPipelineBarrier(cb, kStages, kStages | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, 0, 1, &m, 0, nullptr, 0, nullptr);
}

// ---------------------------------------------------------------- AccelerationStructures

AccelerationStructures::Structure AccelerationStructures::create(VkAccelerationStructureTypeKHR type, VkDeviceSize bytes) {
  Structure s;
  s.storage = Buffer(context_, bytes, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | kAddressed, MemoryUse::DeviceOnly);
  VkAccelerationStructureCreateInfoKHR info{};
  info.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR;
  info.buffer = s.storage.handle();
  info.size = bytes;
  info.type = type;
  vkCheck(fn_.createAccelerationStructure(context_.device(), &info, nullptr, &s.handle), "vkCreateAccelerationStructureKHR");
  VkAccelerationStructureDeviceAddressInfoKHR address{};
  address.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR;
  address.accelerationStructure = s.handle;
  s.address = fn_.getDeviceAddress(context_.device(), &address);
  return s;
}

AccelerationStructures::AccelerationStructures(Context& context, std::span<const Mesh* const> meshes)
    : context_(context), fn_((requireRayTracing(context, "AccelerationStructures"), context.device())),
      instances_(meshes.size()) {
  HC_CHECK_LT(std::size_t{0}, meshes.size());
  const VkDeviceSize scratchAlignment = context.rayTracing().scratchAlignment;
  // The bottom levels: one per distinct mesh, geometry uploaded, built in
  // one submission, each with its own scratch (freed after).
  std::map<const Mesh*, std::size_t> index;
  std::vector<const Mesh*> distinct;
  for (const Mesh* mesh : meshes) {
    HC_CHECK_NE(mesh, nullptr);
    auto [it, inserted] = index.emplace(mesh, distinct.size());
    if (inserted) distinct.push_back(mesh);
    bottomOf_.push_back(it->second);
  }
  std::vector<VkAccelerationStructureGeometryKHR> geometries(distinct.size());
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> builds(distinct.size());
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges(distinct.size());
  // Build inputs and scratch, freed once the bottom levels are built (a
  // structure keeps its own copy of the triangles).
  std::vector<Buffer> scratch, geometry;
  for (std::size_t i = 0; i < distinct.size(); ++i) {
    const Mesh& mesh = *distinct[i];
    Buffer vertices(context, mesh.positions.size() * sizeof(glm::vec3), kBuildInput, MemoryUse::DeviceInput);
    Buffer indices(context, mesh.triangles.size() * sizeof(glm::uvec3), kBuildInput, MemoryUse::DeviceInput);
    {
      BufferUpload up(context, vertices);
      up.write(mesh.positions.data(), mesh.positions.size() * sizeof(glm::vec3));
      up.submit();
    }
    {
      BufferUpload up(context, indices);
      up.write(mesh.triangles.data(), mesh.triangles.size() * sizeof(glm::uvec3));
      up.submit();
    }
    VkAccelerationStructureGeometryKHR& g = geometries[i];
    g.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
    g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    g.geometry.triangles.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    g.geometry.triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    g.geometry.triangles.vertexData.deviceAddress = vertices.deviceAddress();
    g.geometry.triangles.vertexStride = sizeof(glm::vec3);
    g.geometry.triangles.maxVertex = static_cast<std::uint32_t>(mesh.positions.size() - 1);
    g.geometry.triangles.indexType = VK_INDEX_TYPE_UINT32;
    g.geometry.triangles.indexData.deviceAddress = indices.deviceAddress();
    geometry.push_back(std::move(vertices));
    geometry.push_back(std::move(indices));

    VkAccelerationStructureBuildGeometryInfoKHR& b = builds[i];
    b = buildOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, &g);
    const std::uint32_t triangles = static_cast<std::uint32_t>(mesh.triangles.size());
    VkAccelerationStructureBuildSizesInfoKHR sizes{};
    sizes.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
    fn_.getBuildSizes(context.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &b, &triangles, &sizes);
    bottom_.push_back(create(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize));
    b.dstAccelerationStructure = bottom_.back().handle;
    scratch.emplace_back(context, sizes.buildScratchSize + scratchAlignment, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | kAddressed,
                         MemoryUse::DeviceOnly);
    b.scratchData.deviceAddress = alignUp(scratch.back().deviceAddress(), scratchAlignment);
    ranges[i].primitiveCount = triangles;
  }
  context.submit([&](VkCommandBuffer cb) {
    std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> rangePointers;
    for (const VkAccelerationStructureBuildRangeInfoKHR& r : ranges) rangePointers.push_back(&r);
    fn_.cmdBuild(cb, static_cast<std::uint32_t>(builds.size()), builds.data(), rangePointers.data());
  });

  // The top level: its instance records (host-visible, written per frame),
  // storage and scratch sized once for every instance.
  instanceData_ = Buffer(context, instances_ * sizeof(VkAccelerationStructureInstanceKHR), kBuildInput, MemoryUse::Host);
  instanceRecords_.resize(instances_);
  topGeometry_.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR;
  topGeometry_.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  topGeometry_.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  topGeometry_.geometry.instances.data.deviceAddress = instanceData_.deviceAddress();
  VkAccelerationStructureBuildGeometryInfoKHR b = topLevelBuild();
  const std::uint32_t count = static_cast<std::uint32_t>(instances_);
  VkAccelerationStructureBuildSizesInfoKHR sizes{};
  sizes.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR;
  fn_.getBuildSizes(context.device(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &b, &count, &sizes);
  top_ = create(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, sizes.accelerationStructureSize);
  scratch_ = Buffer(context, sizes.buildScratchSize + scratchAlignment, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | kAddressed,
                    MemoryUse::DeviceOnly);
  scratchAddress_ = alignUp(scratch_.deviceAddress(), scratchAlignment);
}

AccelerationStructures::~AccelerationStructures() {
  context_.waitIdle();
  if (top_.handle) fn_.destroyAccelerationStructure(context_.device(), top_.handle, nullptr);
  for (const Structure& s : bottom_) fn_.destroyAccelerationStructure(context_.device(), s.handle, nullptr);
}

VkAccelerationStructureBuildGeometryInfoKHR AccelerationStructures::topLevelBuild() const {
  return buildOf(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, &topGeometry_);
}

void AccelerationStructures::recordTopLevel(VkCommandBuffer cb, std::span<const glm::mat4> objectToWorld) {
  HC_CHECK_EQ(objectToWorld.size(), instances_);
  for (std::size_t i = 0; i < instances_; ++i) {
    VkAccelerationStructureInstanceKHR& r = instanceRecords_[i];
    const glm::mat4& m = objectToWorld[i];
    // VkTransformMatrixKHR is 3 rows × 4 columns, row-major; glm is column-major.
    for (int row = 0; row < 3; ++row)
      for (int col = 0; col < 4; ++col) r.transform.matrix[row][col] = m[col][row];
    r.instanceCustomIndex = static_cast<std::uint32_t>(i);
    // Its own bit, so that a ray can ask what this object alone blocks
    // (shared_rays.h rayMaskOf); the scene's rays see every bit.
    r.mask = shared::rayMaskOf(static_cast<std::uint32_t>(i));
    r.instanceShaderBindingTableRecordOffset = 0;
    // Both faces block, as Embree's rays (no culling).
    r.flags = VK_GEOMETRY_INSTANCE_TRIANGLE_FACING_CULL_DISABLE_BIT_KHR;
    r.accelerationStructureReference = bottom_[bottomOf_[i]].address;
  }
  instanceData_.write(instanceRecords_.data(), instanceRecords_.size() * sizeof(VkAccelerationStructureInstanceKHR));

  VkAccelerationStructureBuildGeometryInfoKHR b = topLevelBuild();
  b.dstAccelerationStructure = top_.handle;
  b.scratchData.deviceAddress = scratchAddress_;
  VkAccelerationStructureBuildRangeInfoKHR range{};
  range.primitiveCount = static_cast<std::uint32_t>(instances_);
  const VkAccelerationStructureBuildRangeInfoKHR* rangePointer = &range;
  fn_.cmdBuild(cb, 1, &b, &rangePointer);
  rayTracingBarrier(cb);
}

// ---------------------------------------------------------------- RayTracingPipeline

RayTracingPipeline::RayTracingPipeline(Context& context, const RayShaders& shaders, std::uint32_t storageBuffers,
                                       std::uint32_t sceneBinding, std::uint32_t pushConstantBytes)
    : context_(context),
      fn_((requireRayTracing(context, "RayTracingPipeline"), context.device())),
      storageBuffers_(storageBuffers),
      sceneBinding_(sceneBinding),
      pushBytes_(pushConstantBytes) {
  HC_CHECK_LE(sceneBinding, storageBuffers);  // the storage buffers are the other bindings, 0 … storageBuffers
  HC_CHECK_LT(0u, shaders.misses.size());
  const VkDevice device = context.device();
  // The stages in order: raygen, the misses, the closest hit if any.
  std::vector<VkShaderModule> modules;
  try {
    std::vector<VkDescriptorSetLayoutBinding> bindings(storageBuffers + 1);
    for (std::uint32_t i = 0; i <= storageBuffers; ++i) {
      bindings[i].binding = i;
      bindings[i].descriptorType =
          i == sceneBinding ? VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      bindings[i].descriptorCount = 1;
      bindings[i].stageFlags = VK_SHADER_STAGE_RAYGEN_BIT_KHR;
    }
    VkDescriptorSetLayoutCreateInfo sl{};
    sl.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    sl.bindingCount = static_cast<std::uint32_t>(bindings.size());
    sl.pBindings = bindings.data();
    vkCheck(vkCreateDescriptorSetLayout(device, &sl, nullptr, &setLayout_), "vkCreateDescriptorSetLayout");
    VkPushConstantRange push{VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, pushConstantBytes};
    VkPipelineLayoutCreateInfo pl{};
    pl.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &setLayout_;
    pl.pushConstantRangeCount = pushConstantBytes ? 1u : 0u;
    pl.pPushConstantRanges = &push;
    vkCheck(vkCreatePipelineLayout(device, &pl, nullptr, &layout_), "vkCreatePipelineLayout");

    const VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, storageBuffers},
                                          {VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1}};
    VkDescriptorPoolCreateInfo dp{};
    dp.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dp.maxSets = 1;
    dp.poolSizeCount = 2;
    dp.pPoolSizes = sizes;
    vkCheck(vkCreateDescriptorPool(device, &dp, nullptr, &pool_), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo ds{};
    ds.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    ds.descriptorPool = pool_;
    ds.descriptorSetCount = 1;
    ds.pSetLayouts = &setLayout_;
    vkCheck(vkAllocateDescriptorSets(device, &ds, &set_), "vkAllocateDescriptorSets");

    const std::uint32_t misses = static_cast<std::uint32_t>(shaders.misses.size());
    const bool closestHit = !shaders.closestHit.empty();
    std::vector<VkPipelineShaderStageCreateInfo> stages;
    auto stage = [&](VkShaderStageFlagBits kind, std::string_view name) {
      modules.push_back(createShaderModule(context, name));
      VkPipelineShaderStageCreateInfo s{};
      s.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
      s.stage = kind;
      s.module = modules.back();
      s.pName = "main";
      stages.push_back(s);
    };
    stage(VK_SHADER_STAGE_RAYGEN_BIT_KHR, shaders.raygen);
    for (const std::string_view miss : shaders.misses) stage(VK_SHADER_STAGE_MISS_BIT_KHR, miss);
    if (closestHit) stage(VK_SHADER_STAGE_CLOSEST_HIT_BIT_KHR, shaders.closestHit);
    // Groups: raygen, each miss, then one triangle hit group: opaque
    // geometry, so a ray that skips closest hits ends at any hit with its
    // payload as it set it ("blocked"); the closest-hit shader, when there
    // is one, runs for the rays that do not skip it.
    std::vector<VkRayTracingShaderGroupCreateInfoKHR> groups(2 + misses);
    for (VkRayTracingShaderGroupCreateInfoKHR& g : groups) {
      g.sType = VK_STRUCTURE_TYPE_RAY_TRACING_SHADER_GROUP_CREATE_INFO_KHR;
      g.generalShader = g.closestHitShader = g.anyHitShader = g.intersectionShader = VK_SHADER_UNUSED_KHR;
    }
    for (std::uint32_t g = 0; g <= misses; ++g) {
      groups[g].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_GENERAL_KHR;
      groups[g].generalShader = g;
    }
    groups[1 + misses].type = VK_RAY_TRACING_SHADER_GROUP_TYPE_TRIANGLES_HIT_GROUP_KHR;
    if (closestHit) groups[1 + misses].closestHitShader = 1 + misses;
    VkRayTracingPipelineCreateInfoKHR rp{};
    rp.sType = VK_STRUCTURE_TYPE_RAY_TRACING_PIPELINE_CREATE_INFO_KHR;
    rp.stageCount = static_cast<std::uint32_t>(stages.size());
    rp.pStages = stages.data();
    rp.groupCount = static_cast<std::uint32_t>(groups.size());
    rp.pGroups = groups.data();
    rp.maxPipelineRayRecursionDepth = 1;
    rp.layout = layout_;
    vkCheck(fn_.createPipelines(device, VK_NULL_HANDLE, VK_NULL_HANDLE, 1, &rp, nullptr, &pipeline_),
            "vkCreateRayTracingPipelinesKHR");
    for (const VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
    modules.clear();

    // The shader binding table: each group's handle at the start of its
    // region, regions aligned to baseAlignment, records to handleAlignment.
    const RayTracingSupport& rt = context.rayTracing();
    const VkDeviceSize handle = rt.handleSize;
    const VkDeviceSize stride = alignUp(handle, rt.handleAlignment);
    const VkDeviceSize region = alignUp(stride, rt.baseAlignment);
    const VkDeviceSize missRegion = alignUp(misses * stride, rt.baseAlignment);
    const std::size_t groupCount = groups.size();
    std::vector<std::uint8_t> handles(groupCount * handle);
    vkCheck(fn_.getGroupHandles(device, pipeline_, 0, static_cast<std::uint32_t>(groupCount), handles.size(), handles.data()),
            "vkGetRayTracingShaderGroupHandlesKHR");
    // Regions: raygen; the misses, `stride` apart; the hit group.
    table_ = Buffer(context, 2 * region + missRegion + rt.baseAlignment,
                    VK_BUFFER_USAGE_SHADER_BINDING_TABLE_BIT_KHR | kAddressed, MemoryUse::Host);
    const VkDeviceAddress base = alignUp(table_.deviceAddress(), rt.baseAlignment);
    const std::size_t offset = static_cast<std::size_t>(base - table_.deviceAddress());
    table_.write(handles.data(), handle, offset);
    for (std::uint32_t m = 0; m < misses; ++m)
      table_.write(handles.data() + (1 + m) * handle, handle, offset + region + m * stride);
    table_.write(handles.data() + (1 + misses) * handle, handle, offset + region + missRegion);
    raygenRegion_ = {base, region, region};  // the raygen region's size equals its stride
    missRegion_ = {base + region, stride, misses * stride};
    hitRegion_ = {base + region + missRegion, stride, stride};
  } catch (...) {
    for (const VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
    destroy();
    throw;
  }
}

RayTracingPipeline::~RayTracingPipeline() { destroy(); }

void RayTracingPipeline::destroy() {
  const VkDevice device = context_.device();
  if (pipeline_) vkDestroyPipeline(device, pipeline_, nullptr);
  if (pool_) vkDestroyDescriptorPool(device, pool_, nullptr);
  if (layout_) vkDestroyPipelineLayout(device, layout_, nullptr);
  if (setLayout_) vkDestroyDescriptorSetLayout(device, setLayout_, nullptr);
  pipeline_ = VK_NULL_HANDLE;
  pool_ = VK_NULL_HANDLE;
  layout_ = VK_NULL_HANDLE;
  setLayout_ = VK_NULL_HANDLE;
}

void RayTracingPipeline::bind(std::initializer_list<BindingAt> buffers, VkAccelerationStructureKHR scene) {
  if (buffers.size() != storageBuffers_) {
    throw std::invalid_argument("RayTracingPipeline::bind: " + std::to_string(buffers.size()) + " buffers for " +
                                std::to_string(storageBuffers_) + " storage bindings");
  }
  std::vector<VkDescriptorBufferInfo> infos(buffers.size());
  std::vector<VkWriteDescriptorSet> writes(buffers.size() + 1);
  std::vector<bool> seen(storageBuffers_ + 1, false);
  std::size_t i = 0;
  for (const BindingAt& b : buffers) {
    if (b.binding > storageBuffers_ || b.binding == sceneBinding_ || seen[b.binding] || !b.resource.buffer) {
      throw std::invalid_argument("RayTracingPipeline::bind: binding " + std::to_string(b.binding) +
                                  " is not a storage buffer binding, is given twice or has no buffer");
    }
    seen[b.binding] = true;
    infos[i] = {b.resource.buffer->handle(), 0, VK_WHOLE_SIZE};
    writes[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    writes[i].dstSet = set_;
    writes[i].dstBinding = b.binding;
    writes[i].descriptorCount = 1;
    writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[i].pBufferInfo = &infos[i];
    ++i;
  }
  VkWriteDescriptorSetAccelerationStructureKHR as{};
  as.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR;
  as.accelerationStructureCount = 1;
  as.pAccelerationStructures = &scene;
  VkWriteDescriptorSet& w = writes.back();
  w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
  w.pNext = &as;
  w.dstSet = set_;
  w.dstBinding = sceneBinding_;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR;
  vkUpdateDescriptorSets(context_.device(), static_cast<std::uint32_t>(writes.size()), writes.data(), 0, nullptr);
}

void RayTracingPipeline::trace(VkCommandBuffer cb, std::uint32_t width, std::uint32_t height, const void* push,
                               std::uint32_t pushBytes) const {
  HC_CHECK_EQ(pushBytes, pushBytes_);
  vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, pipeline_);
  vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_RAY_TRACING_KHR, layout_, 0, 1, &set_, 0, nullptr);
  if (pushBytes) vkCmdPushConstants(cb, layout_, VK_SHADER_STAGE_RAYGEN_BIT_KHR, 0, pushBytes, push);
  if (width && height) fn_.cmdTraceRays(cb, &raygenRegion_, &missRegion_, &hitRegion_, &callableRegion_, width, height, 1);
}

}  // namespace haarcast::gpu
