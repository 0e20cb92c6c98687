// Rays on the device: acceleration structures over posed meshes and a
// ray-tracing pipeline of one ray-generation and one miss shader (the shadow
// rays of a `fused` or `splitsum` frame, shaders/shadow_rays.rgen).
//
// A ray-tracing pipeline rather than ray queries in the compute passes: the
// one data-centre GPU measured (an H100, driver 580) offers
// VK_KHR_ray_tracing_pipeline and not VK_KHR_ray_query (docs/gpu.md).
// Both classes need Context::rayTracing().supported; they throw
// std::runtime_error naming what the device lacks otherwise.
//
//   gpu::AccelerationStructures scene(ctx, meshes);   // bottom levels, built once
//   gpu::RayTracingPipeline rays(ctx, "shadow_rays.rgen", "shadow_rays.rmiss", 10, 10, sizeof(Push));
//   rays.bind({{0, &samples}, …}, scene.topLevel());
//   ctx.submit([&](VkCommandBuffer cb) {
//     scene.recordTopLevel(cb, poses);   // the top level, rebuilt for this frame's poses
//     rays.trace(cb, width, 1, &push, sizeof push);
//   });
#pragma once

#include <cstdint>
#include <initializer_list>
#include <span>
#include <string_view>
#include <vector>

#include <glm/mat4x4.hpp>
#include <vulkan/vulkan.h>

#include "haarcast/core/mesh.h"
#include "haarcast/gpu/buffer.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/gpu/context.h"

namespace haarcast::gpu {

// The device's ray-tracing entry points (extension functions, which the
// loader does not export): loaded once per object from the device.
struct RayFunctions {
  explicit RayFunctions(VkDevice device);
  PFN_vkCreateAccelerationStructureKHR createAccelerationStructure = nullptr;
  PFN_vkDestroyAccelerationStructureKHR destroyAccelerationStructure = nullptr;
  PFN_vkGetAccelerationStructureBuildSizesKHR getBuildSizes = nullptr;
  PFN_vkCmdBuildAccelerationStructuresKHR cmdBuild = nullptr;
  PFN_vkGetAccelerationStructureDeviceAddressKHR getDeviceAddress = nullptr;
  PFN_vkCreateRayTracingPipelinesKHR createPipelines = nullptr;
  PFN_vkGetRayTracingShaderGroupHandlesKHR getGroupHandles = nullptr;
  PFN_vkCmdTraceRaysKHR cmdTraceRays = nullptr;
};

// One bottom-level structure per distinct mesh, built once on the device
// (prefer fast trace); a top level over one instance per mesh given,
// rebuilt by each recordTopLevel from that frame's poses. A rebuild over a
// scene's few instances costs microseconds (docs/gpu.md measures it), so
// there is no refit path.
class AccelerationStructures {
 public:
  // meshes[i]: instance i's mesh (the same pointer twice shares its bottom
  // level). Each must be a valid mesh (Mesh::validate); at least one.
  AccelerationStructures(Context& context, std::span<const Mesh* const> meshes);
  ~AccelerationStructures();
  AccelerationStructures(const AccelerationStructures&) = delete;
  AccelerationStructures& operator=(const AccelerationStructures&) = delete;

  // Writes the instances' object → world transforms (affine, one per mesh
  // given, in order) and records the top level's build, then a barrier that
  // makes it visible to ray-tracing shaders. The previous build must be done
  // (the Context's submissions are waited for).
  void recordTopLevel(VkCommandBuffer cb, std::span<const glm::mat4> objectToWorld);
  VkAccelerationStructureKHR topLevel() const { return top_.handle; }

 private:
  struct Structure {
    Buffer storage;
    VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
    VkDeviceAddress address = 0;
  };
  Structure create(VkAccelerationStructureTypeKHR type, VkDeviceSize bytes);
  // The top level's build: the same for its sizes and for every frame's build.
  VkAccelerationStructureBuildGeometryInfoKHR topLevelBuild() const;

  Context& context_;
  RayFunctions fn_;
  std::size_t instances_ = 0;
  std::vector<Structure> bottom_;      // per distinct mesh
  std::vector<std::size_t> bottomOf_;  // per instance: its bottom level
  Structure top_;
  Buffer instanceData_;  // VkAccelerationStructureInstanceKHR per instance, host-visible
  std::vector<VkAccelerationStructureInstanceKHR> instanceRecords_;  // this frame's, before the write
  VkAccelerationStructureGeometryKHR topGeometry_{};                  // the instances, at instanceData_
  Buffer scratch_;       // the top level's build scratch
  VkDeviceAddress scratchAddress_ = 0;
};

// The shaders of a RayTracingPipeline, by file name (gpu/shaders.h).
struct RayShaders {
  std::string_view raygen;
  std::vector<std::string_view> misses;  // miss index i: misses[i]
  std::string_view closestHit;           // empty: none (the hit group is empty)
};

// A ray-tracing pipeline: one ray-generation shader, its miss shaders, one
// triangle hit group (opaque geometry; empty, so that any hit ends a ray
// that skips closest hits, or with a closest-hit shader for the rays that
// ask which instance they hit), storage buffers at set 0 bindings 0 …
// storageBuffers − 1 and the top level at `sceneBinding`, an optional push
// block; its shader binding table.
class RayTracingPipeline {
 public:
  RayTracingPipeline(Context& context, const RayShaders& shaders, std::uint32_t storageBuffers,
                     std::uint32_t sceneBinding, std::uint32_t pushConstantBytes);
  ~RayTracingPipeline();
  RayTracingPipeline(const RayTracingPipeline&) = delete;
  RayTracingPipeline& operator=(const RayTracingPipeline&) = delete;

  // Every storage binding once, by number, and the top level.
  void bind(std::initializer_list<BindingAt> buffers, VkAccelerationStructureKHR scene);
  // Binds the pipeline and its set, pushes `push` and launches width × height.
  void trace(VkCommandBuffer cb, std::uint32_t width, std::uint32_t height, const void* push = nullptr,
             std::uint32_t pushBytes = 0) const;

 private:
  void destroy();
  Context& context_;
  RayFunctions fn_;
  std::uint32_t storageBuffers_ = 0, sceneBinding_ = 0, pushBytes_ = 0;
  VkDescriptorSetLayout setLayout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  Buffer table_;  // the shader binding table: raygen, miss, hit regions
  VkStridedDeviceAddressRegionKHR raygenRegion_{}, missRegion_{}, hitRegion_{}, callableRegion_{};
};

// Ray-tracing shaders' writes visible to later compute reads (the shadow
// words fused.comp reads) and their reads done before later writes.
void rayTracingBarrier(VkCommandBuffer cb);

}  // namespace haarcast::gpu
