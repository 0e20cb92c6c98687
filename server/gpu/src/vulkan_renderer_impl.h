// VulkanRenderer's state and the steps that build and use it, private to
// server/gpu/src. One file per idea:
//   vulkan_renderer.cpp   construction, the facade, the diagnostics readback
//   scene_upload.cpp      scene data uploaded once, the compute pipelines
//   gbuffer_pass.cpp      the G-buffer's render pass, pipeline, projection, recording
//   frame_buffers.cpp     the per-resolution images and buffers
//   frame_stages.cpp      a frame's uniforms, its stages recorded, submitted and timed
//   fused_frame.cpp       a `fused` or `splitsum` frame: its shadow rays on the device (one submission) or the host's between two
//   device_rays.cpp       the shadow rays on the device: acceleration structures, the ray frame, the four launches
//   rotating_frame.cpp    a frame of the rotating methods: rotation and triple product in batches
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <glm/mat4x4.hpp>

#include "haarcast/gpu/compute.h"
#include "haarcast/gpu/ray_tracing.h"
#include "haarcast/gpu/vulkan_renderer.h"
#include "haarcast/render/embree_scene.h"

namespace haarcast::gpu {

using RendererClock = std::chrono::steady_clock;
inline double secondsSince(RendererClock::time_point t) {
  return std::chrono::duration<double>(RendererClock::now() - t).count();
}

inline constexpr VkFormat kNormalFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
inline constexpr VkFormat kIdsFormat = VK_FORMAT_R32G32B32A32_UINT;
inline constexpr VkFormat kPositionFormat = VK_FORMAT_R32G32B32A32_SFLOAT;
inline constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
inline constexpr std::size_t kRotatedBudget = 256u << 20;  // bytes of rotated coefficients per batch, at most

inline std::uint32_t groupsOf(std::size_t items, std::uint32_t local) {
  return static_cast<std::uint32_t>((items + local - 1) / local);
}

// An image with its memory and view.
struct DeviceImage {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
};

// A stage of a frame: its name (renderer.h) and what it records.
using FrameStage = std::pair<const char*, std::function<void(VkCommandBuffer)>>;
// Timestamps a submission may write within its stages (Impl::markPart).
inline constexpr std::uint32_t kMaxPartMarks = 32;

struct VulkanRenderer::Impl {
  render::RenderOptions options;
  VulkanRendererLimits limits;
  // The scene as both backends prepare it, made once per renderer and
  // shared (read-only) by its frame slots.
  std::shared_ptr<const render::PreparedScene> preparedScene;
  const render::PreparedScene& prepared;
  Context context;
  int level = 0;                 // RenderOptions::level: every object's, or for `fused` the cap (objects at their own: PreparedObject::level)
  std::size_t coefficients = 0;  // N = 4^level
  std::string methodName;

  // ---- Scene data, uploaded once --------------------------------------------
  std::vector<ObjectInfo> objectInfo;
  std::vector<std::uint32_t> triangleCount;
  std::size_t vertexCount = 0, totalTriangles = 0;
  std::vector<std::size_t> visibilityBlocks;  // per global vertex, for the bytes-read count (rotating methods)
  std::size_t rotationBytesPerChannel = 0;    // coefficient bytes one rotation reads (per object: same level)
  std::vector<std::size_t> methodBytesPerChannel;  // per object: method data one rotation reads
  Buffer slices, methodData, positions, normals, triangles, visibility, background;
  Buffer objects, light, frameParams, thresholds;
  // Auto exposure: the frame's two histograms (exposure.comp, cleared each
  // frame) and their read-out (exposure_readout.comp), which the tonemap
  // pass reads on the device and the host from its copy in `exposureOut`.
  Buffer exposureHistograms, exposureResult, exposureOut;
  // The rotating methods' light is device-local (buffer.h); each frame
  // writes it here and records the copy, where it is staged, ahead of the
  // pass that reads it. `fused`'s is made on the device (fused_light.cpp).
  BufferUpload lightUpload;
  // `fused`: the slices in pixel form (texels) and as point values
  // (`pointSlices`, the point lights' lookup), the visibility bits (in
  // `visibility`, every vertex's words in global vertex order), the light in
  // pixel form per frame (in `light`, made by the device), the pixel-centre
  // directions; per frame the point lights (PointLight, kMaxPointLights per
  // object).
  bool fused = false;
  // `splitsum`: no slices, light or visibility; per global lobe (`lobes`,
  // ObjectInfo::sliceBase + t) its SliceLobe, and the prefiltered light.
  // Its frame is fused's (renderFused) with shaders/splitsum.comp as the pass.
  bool splitsum = false;
  // `fused` whose objects hide sky from each other (kObjectSkyHidden).
  bool objectSky() const { return fused && options.objectSky && prepared.standingObjects() >= 2; }
  // `fused` on a ground: the ground's hidden sky (its grid, its sky jobs).
  bool groundSky() const { return fused && prepared.ground; }
  Buffer directions, pointLights, pointSlices;
  // `fused` by cells (RenderOptions::sumTolerance): every slice's detail map
  // (shared::kCellDetailStride apart); the light's cells follow each
  // object's light texels, the cells' centres each level's directions.
  Buffer details;
  // `fused`: per global slice its ∫ρ (vec4) and its lobe (SliceLobe), and
  // the prefiltered light (core/prefiltered_light.h) the lobe path reads.
  Buffer sliceEnergy, lobes, lobeLight;
  BufferUpload pointLightUpload;
  // fused.comp reads these through texel views (BindingKind::Texels).
  TexelView sliceTexels, lightTexels, directionTexels, visibilityTexels, lobeLightTexels, pointSliceTexels, detailTexels;
  // `fused`'s light, made on the device each frame (fused_light.cpp,
  // shaders/light.comp) from the rest map at each object's turn level
  // (once per level, RGB0 texels) and that level's directions in
  // `directions`; per object, where its rest map starts, its level and
  // where its directions start (LightPush).
  Buffer lightRestMaps;
  std::vector<LightPush> lightRestOf;
  std::unique_ptr<ComputePipeline> lightPass;
  // Per object, what its light in `light` was made for (its rotation, the
  // light's and the ground's, as render::FusedLightCache keys it): a frame
  // that turns none of them records no texels for it, so an orbiting camera
  // pays only the ground's sum. Empty while a frame that remakes it is in
  // flight or was stopped (then the buffer may hold either light).
  // `lightMaking`: what the frame being recorded makes, moved into
  // `lightMadeFor` once its submission has run (fusedLightMade).
  std::vector<std::optional<render::FusedLightCache::Key>> lightMadeFor, lightMaking;
  std::size_t lightsMadeLastFrame = 0;
  std::vector<PointLight> pointLightData;         // this frame's point lights, before upload
  std::uint32_t fusedGroups = 0;     // the most workgroups of the fused dispatch
  std::uint32_t fusedLocal = 0;      // its local size
  std::size_t fusedLightTexelCount = 0;  // Σ over objects of N at each one's level (+ 2K by cells)
  // Where the shadow rays are traced (VulkanRendererLimits::rays, resolved
  // when the renderer is built): on the device (device_rays.cpp) or by Embree
  // on the host (`rays` below). The rotating methods trace none.
  bool deviceRays = false;
  // The device's: a bottom level per mesh and the frame's top level, the
  // ray-generation pipeline, per frame the objects' and the frame's records
  // (core/shared_rays.h); the map light, rgb and luminance (the hidden
  // sky); per pixel its centre sample and the coarse grid's values; the
  // sky jobs' list and their lanes' sums (shared_rays.h), skyJobCapacity jobs.
  std::unique_ptr<AccelerationStructures> accelerationStructures;
  std::unique_ptr<RayTracingPipeline> shadowRays;
  Buffer rayObjects, rayFrame, skyLight, pixelSample, skyGrid, skyJobs, skyPartials;
  std::uint32_t skyJobCapacity = 0;
  BufferUpload rayObjectsUpload, rayFrameUpload;
  std::vector<RayObject> rayObjectData;
  RayFrame rayFrameData{};
  std::vector<glm::mat4> posesData;  // this frame's object → world, for the top level
  // The samples' launches are this many invocations wide (and as many rows
  // as the sample capacity needs): under every device's launch-width limit.
  static constexpr std::uint32_t kRaysLaunchWidth = 4096;
  // The point lights' shadow rays (render/point_lights.h), on the host: every
  // prepared object as an instance, posed per frame (setTransform), as the
  // CPU backend's ray scene.
  std::unique_ptr<RayScene> rays;

  // ---- Pipelines ---------------------------------------------------------------
  std::unique_ptr<ComputePipeline> rotate, rotationInput, tripleProduct, resolve, exposure, exposureReadout, tonemap,
      fusedPass, batchArgsPass;
  VkRenderPass renderPass = VK_NULL_HANDLE;
  VkDescriptorSetLayout gbufferSetLayout = VK_NULL_HANDLE;
  VkPipelineLayout gbufferLayout = VK_NULL_HANDLE;
  VkPipeline gbufferPipeline = VK_NULL_HANDLE;
  VkDescriptorPool gbufferPool = VK_NULL_HANDLE;
  VkDescriptorSet gbufferSet = VK_NULL_HANDLE;

  // ---- Per resolution --------------------------------------------------------
  int width = 0, height = 0;
  std::size_t batch = 0, maxBatches = 0, lastBatches = 0;
  // Shaded samples a frame may have: one per pixel, or with antialiasing
  // kSubsamples per pixel (an edge pixel has no centre sample).
  std::size_t sampleCapacity = 0;
  // The G-buffer's attachments and framebuffer at one scale of the frame.
  struct GBufferTarget {
    DeviceImage normal, ids, position, depth;
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    std::uint32_t width = 0, height = 0;
  };
  GBufferTarget target;     // the pixel centres
  GBufferTarget subTarget;  // antialiasing: the sub-samples, at twice the resolution
  // What the passes write and read stays in device-local memory: a GPU's
  // passes never touch system memory over the bus (on an H100 the counter's
  // atomics and the samples in system memory made rotation-input 37 ms at
  // 1080p). The host reads only copies (Readback):
  Buffer gbufIds, gbufNormals, gbufPositions, samples, shade, counter, radiance, rgba8, rotated;
  // the covered count and indirect arguments, copied after rotation-input;
  Buffer counterOut;
  // the covered samples' ShadeSamples where the host traces their rays or
  // counts their bytes, copied on demand (readShadeSamples);
  Buffer shadeOut;
  // the frame's linear image and G-buffer ids (the object mask), copied
  // from `radiance` and `gbufIds` only when a request asks for the linear image;
  Buffer radianceOut, idsOut;
  // `fused`: per object its samples shaded from one slice and from two
  // (fused.comp), cleared each frame, and their copy for the bytes-read count.
  Buffer sliceCounts, sliceCountsOut;
  // `fused`: per covered sample its point-light shadow bits (bit k: sees
  // light k), computed on the host between the frame's two submissions.
  Buffer masks;
  BufferUpload maskUpload;
  std::vector<std::uint32_t> maskData;  // this frame's masks, before upload
  // `fused` with objects that hide sky from each other (kObjectSkyHidden):
  // per covered sample its HiddenLight (shared_rays.h), else one record.
  Buffer hidden;
  BufferUpload hiddenUpload;
  // `fused`'s smooth sum (shared_smooth.h): two vec4 per pixel, cleared
  // each frame that takes sums from neighbours (RenderOptions::smoothSumTolerance).
  Buffer smoothSums;
  // Its stage lists: per stage the samples its dispatch shades, and that
  // dispatch's arguments (shared_smooth.h smoothListOffset).
  Buffer smoothLists;
  std::vector<HiddenLight> hiddenData;
  // Antialiasing: the sub-samples' ids and normals (else 4-byte stand-ins),
  // and each pixel's edge word (shared_layout.h kEdgeFlag).
  Buffer subIds, subNormals, edges;
  // The rotating methods: per batch, the indirect arguments of its rotation
  // and triple product (DispatchArgs, written by batch_args.comp).
  Buffer batchArgs;
  // Stage timing: timestamps around each stage's submission on GPUs; on a
  // CPU device (lavapipe), the host's wall time of the submission, because
  // lavapipe's timestamps do not wait for compute dispatches (measured: 0.8 s
  // of timestamps in a 3.8 s submission). On a CPU device, host time is device time.
  bool useTimestamps = false;
  VkQueryPool queries = VK_NULL_HANDLE;
  std::uint32_t queryCapacity = 0;  // timestamps the pool holds
  // markPart's marks in the submission being recorded: name, the stage it
  // is in, its query; markStage: that stage (-1: not recording timestamps).
  struct PartMark {
    const char* name;
    std::uint32_t stage, query;
  };
  std::vector<PartMark> partMarks;
  int markStage = -1;
  std::uint32_t nextPartQuery = 0, partQueryEnd = 0;
  // The request's `cancelled` while render() runs (null otherwise): polled
  // by runStages before each submission, the batch boundary of a frame.
  const std::function<bool()>* cancelled = nullptr;
  bool cancelRequested() const { return cancelled && *cancelled && (*cancelled)(); }

  // vulkan_renderer.cpp
  // Throws std::invalid_argument for options the GPU passes cannot take,
  // before anything is prepared.
  static void checkOptions(const render::RenderOptions& o);
  Impl(std::shared_ptr<const render::PreparedScene> scene, const render::RenderOptions& o, const VulkanOptions& vulkan,
       const VulkanRendererLimits& l);
  ~Impl();
  render::Frame render(const render::FrameRequest& request);

  // scene_upload.cpp
  void uploadScene();
  void createFusedPipeline(std::uint32_t local);
  void createSplitsumPipeline();

  // fused_light.cpp: `fused`'s "light" stage, the rest maps uploaded once
  // and each object's light in its frame recorded every frame.
  void createFusedLight(const DirectionTable& directionTable);
  void recordFusedLight(VkCommandBuffer cb, const render::ResolvedFrame& resolved);
  // After the submission that held the light stage ran to its end: the
  // lights it made are what `light` holds.
  void fusedLightMade();

  // gbuffer_pass.cpp
  void createGraphicsPipeline();
  // Rasterises every object, posed and projected as the resolved frame
  // says, into `t` and copies the attachments to the buffers given
  // (positions: null to skip).
  void rasterise(VkCommandBuffer cb, const render::ResolvedFrame& resolved, const GBufferTarget& t, const Buffer& ids,
                 const Buffer& normals, const Buffer* positions);
  // The frame's G-buffer, and with antialiasing the sub-samples' as well.
  void recordGBuffer(VkCommandBuffer cb, const render::ResolvedFrame& resolved);

  // frame_buffers.cpp
  void ensureResolution(int w, int h);
  void releaseResolution();
  DeviceImage createImage(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect, std::uint32_t w,
                          std::uint32_t h);
  void destroyImage(DeviceImage& image);
  GBufferTarget createTarget(std::uint32_t w, std::uint32_t h);
  void destroyTarget(GBufferTarget& t);

  // frame_stages.cpp
  // The frame's uniforms (camera, light turn, exposure, the fused dispatch's
  // workgroup count) and the sRGB thresholds of its exposure.
  void uploadFrameUniforms(const render::FrameRequest& request, const render::ResolvedFrame& resolved);
  // The "tonemap" stage: resolve (backdrop, antialiased edge pixels), the
  // exposure (measured and chosen on the device, exposure.comp), encoding.
  void recordTonemap(VkCommandBuffer cb, const render::FrameRequest& request);
  // The exposure the device measured and used (Frame::logAverageLuminance, exposureStops).
  void finishExposure(const render::FrameRequest& request, render::Frame& frame) const;
  // With the linear image asked for: the image and the object mask from
  // their copies (recordTonemap).
  void readLinearImage(render::Frame& frame) const;
  // The stages of a frame, in order: with timestamps, recorded into one
  // command buffer (a timestamp after each) and submitted once; otherwise
  // (a CPU device) one submission per stage, timed on the host. Stages of
  // one name (the batches of rotation and triple-product) add up to one
  // entry of frame.stages, at the place of the first. Stops before a
  // submission once cancelRequested(), with frame.cancelled set. Each
  // stage is entered (render::enterFrameStage) as it is submitted; one
  // submission of every stage is the first stage's, for a watcher.
  void runStages(const std::vector<FrameStage>& stages, const render::FrameRequest& request, render::Frame& frame);
  // A timestamp after everything recorded so far in the stage being
  // recorded, named `part` (render::Frame::parts): only inside runStages's
  // timestamped submission; elsewhere (CPU devices) nothing.
  void markPart(VkCommandBuffer cb, const char* part);
  void ensureQueries(std::uint32_t count);

  // fused_frame.cpp
  // A `fused` frame, or a `splitsum` one: the same stages with splitsum.comp
  // as the pass ("splitsum") and no light or point lights to upload.
  render::Frame renderFused(const render::FrameRequest& request);
  // The "shadow-rays" stage: the covered samples read back, each one's
  // point-light mask (render::pointLightMask against `rays`, posed for this
  // frame) written for the upload. Returns the covered count.
  std::uint32_t computeShadowMasks(const render::ResolvedFrame& resolved, const glm::vec3& eye);
  // The covered count rotation-input left (counterOut), checked against the capacity.
  std::uint32_t coveredSamples() const;
  // The first `covered` ShadeSamples, copied from the device into shadeOut.
  const ShadeSample* readShadeSamples(std::uint32_t covered);
  // Records the copy of the counter into counterOut (after rotation-input).
  void recordCounterCopy(VkCommandBuffer cb);

  // The host's ray scene (`rays`), for the rays Embree traces.
  void createHostRays();

  // device_rays.cpp
  // Resolves limits.rays for this device and method (deviceRays); throws
  // std::invalid_argument when `device` is asked for and the device has no
  // ray tracing.
  void chooseRays();
  // The acceleration structures, the pipeline and the buffers the frame's
  // size does not change (after uploadScene). Under `auto`, a device that
  // offers ray tracing but fails to set it up (a driver's error) falls back
  // to the host's rays, with a warning on stderr; under `device` it throws.
  void createDeviceRays();
  void setUpDeviceRays();
  // The per-pixel and per-grid-point buffers (ensureResolution).
  void ensureDeviceRayBuffers();
  // This frame's RayObject and RayFrame records, written for their upload.
  void writeRays(const render::ResolvedFrame& resolved, const glm::vec3& eye);
  // The "shadow-rays" stage on the device: the uploads, the top level, the
  // four launches (core/shared_rays.h), ending with the masks fused reads.
  shared::FusedPush fusedPush(shared::uint stage, shared::uint part, float tolerance) const;
  // Where the stages' lists of their own sums start in smoothLists, in words.
  shared::uint smoothOwnLists() const;
  void recordSmoothStages(VkCommandBuffer cb);
  void recordDeviceRays(VkCommandBuffer cb);
  // The device traces the objects' hidden sky per smooth-sum stage, only for
  // the samples a stage sums itself (shared_rays.h RaysPush::stagedHidden).
  bool hiddenPerStage() const;
  RaysPush raysPush(shared::uint phase, shared::uint stage = 0) const;
  void recordStageHidden(VkCommandBuffer cb, shared::uint stage);

  void recordSkyJobs(VkCommandBuffer cb, std::uint32_t phase, std::uint32_t across, std::uint32_t down,
                     const char* listed, const char* traced);

  // rotating_frame.cpp
  render::Frame renderRotating(const render::FrameRequest& request);
};

}  // namespace haarcast::gpu
