// The Vulkan backend behind render::Renderer (docs/gpu.md): the seed's
// passes as Vulkan work, each timed on the device with timestamp queries
// under the shared stage names of renderer.h:
//   light           `fused`: compute, each object's light in its frame (shaders/light.comp,
//                   fused_light.cpp); the rotating methods: host, render::lightInObjectFrame
//                   per object (the Haar cut keeps each channel's k largest), uploaded
//   gbuffer         graphics pipeline, offscreen: normal, ids + barycentrics, position
//   rotation-input  compute: slice index and Y-X-Y angles per covered pixel, compacted;
//                   then every batch's indirect arguments (batch_args.comp)
//   rotation        compute: shaders/rotate_<method>.comp, in batches of covered pixels
//   triple-product  compute: light × rotated slice × interpolated visibility
//   shadow-rays     `fused` and `splitsum`: on a device that traces rays, its
//                   ray-generation shader (device_rays.cpp); else on the host, the covered
//                   samples read back, one Embree shadow ray per sample and point light
//                   (render::pointLightMask; splitsum: its mirror ray alone), the masks uploaded
//   fused           `fused` only, in place of rotation and triple-product:
//                   shaders/fused.comp, one indirect dispatch sized by rotation-input
//   splitsum        `splitsum` only, in its place: shaders/splitsum.comp, one
//                   invocation per sample, the same indirect dispatch
//   tonemap         compute: backdrop and antialiased edge pixels (resolve.comp),
//                   auto exposure measured and chosen (exposure.comp), RGBA8;
//                   the linear image kept
// Antialiasing (RenderOptions::antialias) follows the CPU backend's rule
// (shared_layout.h): the G-buffer is also rasterised at twice the
// resolution, whose pixel centres are the sub-samples; rotation-input
// shades the covered sub-samples of edge pixels in place of their centres,
// so every method shades them through the same sample list.
// The rotating methods record their frame as one command buffer (timestamps
// per stage on GPUs; one submission per stage, host-timed, on CPU devices)
// and read the covered count back only when the frame is done. `fused`
// (and `splitsum`) with the device's rays is one submission too, from its
// light to its RGBA8 bytes; with the host's it submits twice: [light,
// gbuffer, rotation-input], then, after the host's shadow rays for the
// samples read back, [fused (splitsum), tonemap].
// Scene data (slices, method data, meshes, visibility, backdrop) is uploaded
// once, into device-local memory (staged where the host cannot map it);
// frame buffers are allocated once per resolution and reused, so a frame at
// an unchanged resolution allocates no device memory.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <glm/vec4.hpp>

#include "haarcast/gpu/context.h"
#include "haarcast/gpu/passes.h"
#include "haarcast/render/backend_names.h"
#include "haarcast/render/renderer.h"

namespace haarcast::gpu {

// Frames in flight on a GPU by default. Measured on the H200 (docs/gpu.md,
// service at 1280×720, four clients, one queue): two gave 6.23 frames a
// second each, one 5.91, four 5.79; a frame fills the device, so a second
// slot pays only by overlapping one frame's host work (the light, the
// readback) with another's passes. Each slot's buffers are its own (about
// 0.7 KiB a pixel antialiased: docs/gpu.md, Buffers).
inline constexpr std::size_t kDefaultGpuFramesInFlight = 2;

// Options of the Vulkan backend beyond the device (context.h VulkanOptions).
struct VulkanRendererLimits {
  // Covered pixels rotated per batch (the rotated buffer holds batch·3·N
  // floats); 0 = as many as fit in 256 MiB and the device's storage-buffer
  // range and dispatch limits.
  std::size_t batchSamples = 0;
  // Workgroup size of rotate_spatial.comp; 0 = 64 on CPU devices, 256 on GPUs.
  std::uint32_t spatialLocalSize = 0;
  // `fused`: workgroup size (0 = the subgroup size on CPU devices, 256 on
  // GPUs) and the most workgroups in flight (0 = 512 on CPU devices, 65,536 on
  // GPUs, at most the device's limit).
  std::uint32_t fusedLocalSize = 0;
  std::uint32_t fusedGroups = 0;
  // `fused` by cells: a subgroup sums its fine and mixed cells together
  // (shared_passes.h kSpecCellsTogether) where the device can; false: each
  // invocation its own (the path of devices that cannot).
  bool cellsTogether = true;
  // Frames that may render at once, each with its own device buffers,
  // command buffers, host scratch and queue where the device was opened
  // with enough (VulkanOptions::queues, queue_lender.h; the prepared scene
  // is shared, its device copy uploaded once per frame in flight): 0 = 1 on
  // a CPU device (lavapipe's frames share its cores and its one queue),
  // kDefaultGpuFramesInFlight on a GPU. While one frame's host stages run
  // (the light, the readback, the encoding after it), another's passes run;
  // frames on different queues also run side by side on the device.
  std::size_t framesInFlight = 0;
  // Where the shadow rays of `fused` and `splitsum` are traced
  // (render/backend_names.h): `device` needs a device with ray tracing
  // (context.h, RayTracingSupport) and is refused elsewhere.
  render::RayMode rays = render::RayMode::Auto;
  // With the device's rays and a ground: the most sky jobs (a ground
  // point's hidden-sky rays spread over shared::kSkyLanes invocations,
  // core/shared_rays.h) one launch's list holds; a job past it traces its
  // rays in one invocation. 0 = the fine grid's points (every grid point
  // fits; a sample's own rays past it are rare). Memory: kSkyLanes + 2 words a job.
  std::size_t skyJobs = 0;
  // On a CPU device each stage is a submission of its own, timed on the host
  // (lavapipe's timestamps do not wait for compute); true records the frame
  // into one submission there too, reported as one stage, "device".
  bool oneSubmission = false;
};

class VulkanRenderer final : public render::Renderer {
 public:
  // Throws std::invalid_argument for options the GPU passes cannot take
  // (levels outside kMinGpuLevel..kMaxGpuLevel, a method whose shader is not
  // built) and std::runtime_error for Vulkan failures, naming the call.
  VulkanRenderer(const render::Scene& scene, const render::RenderOptions& options, const VulkanOptions& vulkan,
                 const render::RenderProgress& progress = {}, const VulkanRendererLimits& limits = {});
  ~VulkanRenderer() override;

  std::string backend() const override { return std::string(render::kVulkanBackend); }
  std::string deviceName() const override;
  std::string rays() const override;
  const render::RenderOptions& options() const override;
  std::size_t objectCount() const override;
  std::vector<int> objectLevels() const override;
  std::vector<int> pointLightLevels() const override;
  std::vector<std::string> objectPlans() const override;
  bool concurrentRenders() const override { return slots_.size() > 1; }
  std::size_t framesInFlight() const override { return slots_.size(); }
  // Waits for a free frame slot (one of framesInFlight()), renders in it.
  render::Frame render(const render::FrameRequest& request) override;
  // The most frames that have rendered at once so far.
  std::size_t peakFramesInFlight() const;
  // The queue each frame slot submits to (Context::queueIndex), in slot order.
  std::vector<std::uint32_t> slotQueues() const;

  // ---- For tests and diagnostics: the last frame's intermediate data -----
  // (of the slot that finished a frame last; call between frames)
  Context& context();
  const render::PreparedScene& prepared() const;
  // G-buffer per pixel: (object + 1 or 0, triangle, u bits, v bits), the
  // object-frame normal and position (w unused).
  std::vector<glm::uvec4> gbufferIds() const;
  std::vector<glm::vec4> gbufferNormals() const;
  std::vector<glm::vec4> gbufferPositions() const;
  // The compacted covered pixels, in the order the GPU wrote them.
  std::vector<RotationSample> rotationSamples() const;
  std::vector<ShadeSample> shadeSamples() const;
  // `fused`, `splitsum`: each covered sample's shadow word as the pass read
  // it (point-light bits, kLobeSeenBit, the ground's occlusion), in
  // shadeSamples() order; empty for the rotating methods.
  std::vector<std::uint32_t> shadowWords() const;
  // `fused` whose objects hide sky from each other: each covered sample's
  // HiddenLight (core/shared_rays.h) as the pass read it, in shadeSamples()
  // order (the ground's are not written); else empty.
  std::vector<HiddenLight> hiddenLights() const;
  // With antialiasing, each pixel's edge word (shared_layout.h kEdgeFlag);
  // empty without.
  std::vector<std::uint32_t> edgeWords() const;
  // `fused`: the light texels the pass read (ObjectInfo::lightBase, N per
  // object at its level, then by cells its cells' power and centroids:
  // shaders/light.comp) and the ObjectInfo records (the ground's
  // groundRadiance as the device made it); else empty.
  std::vector<glm::vec4> lightTexels() const;
  std::vector<ObjectInfo> objectInfos() const;
  // `fused`: how many objects' light texels the last frame's light stage
  // made (the others' were made for the same turns by an earlier frame).
  std::size_t lightsMadeLastFrame() const;
  std::size_t batchSamples() const;  // the batch size in use (0 before the first frame)
  std::size_t batchesLastFrame() const;

 private:
  struct Impl;
  Impl& last() const;
  // One Impl per frame in flight; `busy_` and `last_` under mutex_.
  std::vector<std::unique_ptr<Impl>> slots_;
  mutable std::mutex mutex_;
  std::condition_variable freed_;
  std::vector<bool> busy_;
  std::size_t last_ = 0, inFlight_ = 0, peak_ = 0;
};

std::unique_ptr<render::Renderer> makeVulkanRenderer(const render::Scene& scene, const render::RenderOptions& options,
                                                     const VulkanOptions& vulkan,
                                                     const render::RenderProgress& progress = {},
                                                     const VulkanRendererLimits& limits = {});

}  // namespace haarcast::gpu
