// A `fused` frame: G-buffer → rotation input (compaction, indirect
// arguments) → shadow rays → fused (vkCmdDispatchIndirect) → tonemap. A
// `splitsum` frame is the same with splitsum.comp as the pass, its rays the
// mirror rays alone. With the rays on the device (device_rays.cpp) the frame
// is one submission (on devices with timestamps, or with
// VulkanRendererLimits::oneSubmission). With the host's (Embree, the CPU
// backend's rays for the same hit: render/point_lights.h) it is two, around
// the covered samples read back and their shadow words uploaded.

#include <array>
#include <algorithm>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>

#include "haarcast/core/check.h"
#include "haarcast/core/fused.h"
#include "haarcast/core/parallel.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/shared_smooth.h"
#include "haarcast/core/splitsum.h"
#include "haarcast/render/point_lights.h"
#include "haarcast/render/shading.h"

#include "vulkan_renderer_impl.h"

namespace haarcast::gpu {

std::uint32_t VulkanRenderer::Impl::computeShadowMasks(const render::ResolvedFrame& resolved, const glm::vec3& eye) {
  const std::uint32_t covered = coveredSamples();
  const std::size_t objectCount = prepared.objects.size();
  for (std::size_t i = 0; i < objectCount; ++i) rays->setTransform(i, glm::mat4(resolved.objects[i].objectToWorld));
  std::vector<glm::mat4> toWorld;
  std::vector<glm::mat3> rotations;
  for (const render::ResolvedObject& o : resolved.objects) {
    toWorld.emplace_back(o.objectToWorld);
    rotations.emplace_back(o.rotation);
  }
  // The samples as rotation-input wrote them, copied to the host, in chunks
  // of samples (parallelFor hands out one index at a time, under a lock).
  const ShadeSample* sh = readShadeSamples(covered);
  std::vector<std::uint32_t>& out = maskData;
  out.resize(covered);
  // The sky other objects hide from each object sample (render::objectSkyHidden).
  const bool hides = objectSky();
  if (hides) hiddenData.assign(covered, HiddenLight{});
  constexpr std::size_t kChunk = 256;
  const std::span<const glm::vec3> lightDirections = resolved.pointLightDirections;
  auto pointOf = [&](const ShadeSample& sample) {
    const std::size_t object = sample.object;
    const render::PreparedObject& p = prepared.objects[object];
    const std::uint32_t base = objectInfo[object].vertexBase;
    // The hit triangle in the object's own vertex ids, as the CPU backend passes it.
    const glm::uvec3 triangle(sample.vertex[0] - base, sample.vertex[1] - base, sample.vertex[2] - base);
    return render::shadingPoint(*p.mesh, triangle, sample.b, toWorld[object], rotations[object],
                                p.shadowShift * static_cast<float>(resolved.objects[object].scale));
  };
  // The ground's hidden sky on the coarse grid (render/point_lights.h),
  // from the interior pixels' centre samples (slot < pixels), as the CPU.
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  render::GroundSkyGrid sky(static_cast<int>(width), static_cast<int>(height));
  // splitsum shades its ground as any object (core/splitsum.h): no hidden sky.
  const bool groundSky = this->groundSky();
  if (groundSky) {
    std::vector<std::uint32_t> centreOf(pixels, ~0u);
    for (std::size_t s = 0; s < covered; ++s)
      if (sh[s].pixel < pixels && sh[s].object < objectCount) centreOf[sh[s].pixel] = static_cast<std::uint32_t>(s);
    auto ground = [&](std::size_t pixel) {
      const std::uint32_t s = centreOf[pixel];
      return s != ~0u && prepared.objects[sh[s].object].ground;
    };
    sky.compute(*rays, resolved.skyOccluders, [&](std::size_t pixel) -> std::optional<render::ShadingPoint> {
      // Interior ground pixels only (the 3×3 rule of shared_layout.h), with
      // antialiasing or without: with it, only they have a centre sample.
      if (!ground(pixel)) return std::nullopt;
      if (!options.antialias && !render::interiorPixel(pixel, static_cast<std::size_t>(width), static_cast<std::size_t>(height), ground))
        return std::nullopt;
      return pointOf(sh[centreOf[pixel]]);
    }, options.threads);
  }
  parallelFor((covered + kChunk - 1) / kChunk, [&](std::size_t chunk) {
    const std::size_t begin = chunk * kChunk;
    const std::size_t end = std::min<std::size_t>(covered, (chunk + 1) * kChunk);
    // The point lights' rays for the chunk's samples at once, in packets
    // (render::pointLightMasks); samples off every object (a zero normal
    // faces no light) cast none.
    thread_local std::vector<render::ShadingPoint> points;
    thread_local std::vector<std::uint32_t> lightMasks;
    thread_local std::vector<std::uint8_t> onGround;
    points.resize(end - begin);
    onGround.resize(end - begin);
    for (std::size_t s = begin; s < end; ++s) {
      const bool object = sh[s].object < objectCount;
      points[s - begin] = object ? pointOf(sh[s]) : render::ShadingPoint{{}, glm::vec3(0.0f), 0.0f};
      onGround[s - begin] = object && prepared.objects[sh[s].object].ground ? 1 : 0;
    }
    lightMasks.resize(points.size());
    render::pointLightMasks(*rays, points, lightDirections, lightMasks,
                            render::GroundRays{resolved.skyOccluders.occluders, onGround});
    for (std::size_t s = begin; s < end; ++s) {
      const ShadeSample& sample = sh[s];
      if (sample.object >= objectCount) {
        out[s] = 0;
        continue;
      }
      const render::ShadingPoint& point = points[s - begin];
      out[s] = lightMasks[s - begin];
      if (prepared.objects[sample.object].lobePath) out[s] |= render::lobeRayBit(*rays, point, eye);
      if (hides && !prepared.objects[sample.object].ground) {
        hiddenData[s] = render::hiddenLightOf(render::objectSkyHidden(*rays, point, sample.object, resolved.skyOccluders),
                                              rotations[sample.object]);
      }
      if (groundSky && prepared.objects[sample.object].ground) {
        // Its pixel: the slot itself, or the edge pixel a sub-sample's slot belongs to.
        const std::size_t pixel = sample.pixel < pixels ? sample.pixel : (sample.pixel - pixels) / shared::kSubsamples;
        out[s] = render::withGroundOcclusion(
            out[s], sky.at(pixel, [&] { return render::groundSkyOcclusion(*rays, point, resolved.skyOccluders); }));
      }
    }
  }, {}, options.threads);
  if (!out.empty()) maskUpload.write(out.data(), out.size() * sizeof(std::uint32_t));
  if (hides && !hiddenData.empty()) hiddenUpload.write(hiddenData.data(), hiddenData.size() * sizeof(HiddenLight));
  return covered;
}

// The smooth sum's stages as bench-frame's profile names them (Frame::parts).
constexpr std::array<const char*, shared::kSmoothSumStages> kSmoothStageParts{
    "grid sums", "step 4 edges", "step 4 centres", "step 2 edges", "step 2 centres", "step 1 edges", "step 1 centres"};

shared::FusedPush VulkanRenderer::Impl::fusedPush(shared::uint stage, shared::uint part, float tolerance) const {
  shared::FusedPush push{};
  push.stage = stage;
  push.width = static_cast<shared::uint>(width);
  push.height = static_cast<shared::uint>(height);
  push.tolerance = tolerance;
  push.groups = fusedGroups;
  push.part = part;
  push.ownLists = smoothOwnLists();
  return push;
}

// The smooth sum's stages, coarse to fine, each reading the ones before:
// first every covered sample into its stage's list, so that each stage's
// dispatches take its own samples rather than every workgroup passing over
// every sample to find them; then per stage one invocation a sample decides
// (a sum taken from the parents is shaded there), and a workgroup a sample
// sums the rest (shared_smooth.h).
void VulkanRenderer::Impl::recordSmoothStages(VkCommandBuffer cb) {
  vkCmdFillBuffer(cb, smoothSums.handle(), 0, VK_WHOLE_SIZE, 0u);
  // Counts 0; where each stage's list starts; each dispatch (0, 1, 1).
  std::array<std::uint32_t, shared::kSmoothListHeader> header{};
  for (shared::uint stage = 0; stage < shared::kSmoothSumStages; ++stage) {
    header[shared::kSmoothListOffsets + stage] =
        shared::smoothListOffset(stage, static_cast<shared::uint>(width), static_cast<shared::uint>(height));
    for (const shared::uint args : {shared::kSmoothDecideArgs, shared::kSmoothSumArgs}) {
      header[args + 4 * stage + 1] = 1;
      header[args + 4 * stage + 2] = 1;
    }
  }
  vkCmdUpdateBuffer(cb, smoothLists.handle(), 0, sizeof header, header.data());
  computeBarrier(cb);
  // An invocation a sample: as many workgroups as the samples that can be
  // covered fill (at most fusedGroups; the invocations past the covered
  // count return at once), not the shading dispatch's workgroup a sample.
  const shared::FusedPush list = fusedPush(shared::kSmoothSumList, 0, 0.0f);
  fusedPass->dispatch(cb, {std::min(groupsOf(sampleCapacity, fusedLocal), fusedGroups), 1, 1}, &list, sizeof list);
  markPart(cb, "stage lists");
  for (shared::uint stage = 0; stage < shared::kSmoothSumStages; ++stage) {
    for (const shared::uint part : {shared::kSmoothPartDecide, shared::kSmoothPartSum}) {
      computeBarrier(cb);  // the lists and their dispatches; each stage's sums, for the next
      // The hidden sky of the samples the stage sums itself, traced now (stage 0's with the masks).
      if (part == shared::kSmoothPartSum && stage > 0 && hiddenPerStage()) recordStageHidden(cb, stage);
      const shared::FusedPush push = fusedPush(stage, part, options.smoothSumTolerance);
      const shared::uint args = part == shared::kSmoothPartDecide ? shared::kSmoothDecideArgs : shared::kSmoothSumArgs;
      fusedPass->dispatchIndirect(cb, smoothLists, (args + 4 * stage) * sizeof(std::uint32_t), &push, sizeof push);
    }
    markPart(cb, kSmoothStageParts[stage]);
  }
}

render::Frame VulkanRenderer::Impl::renderFused(const render::FrameRequest& request) {
  const auto start = RendererClock::now();
  render::Frame frame;
  frame.width = request.width;
  frame.height = request.height;

  // ---- What the host resolves: poses, camera and point lights, one number
  // per object or light (render::resolveFrame, which checks the request),
  // written into the frame's records. The map light itself is the device's
  // first stage ("light", fused_light.cpp).
  const render::ResolvedFrame resolved = render::resolveFrame(prepared, options, request, render::FusedMapLight::Device);
  ensureResolution(request.width, request.height);
  const std::size_t objectCount = prepared.objects.size();
  const std::size_t lightCount = resolved.pointLightDirections.size();
  HC_CHECK_LE(lightCount, std::size_t{shared::kMaxPointLights});
  for (std::size_t i = 0; i < objectCount; ++i) {
    const render::ResolvedObject& o = resolved.objects[i];
    ObjectInfo& info = objectInfo[i];
    for (int c = 0; c < 3; ++c) info.rotation[c] = glm::vec4(glm::vec3(o.rotation[c]), 0.0f);
    for (int c = 0; c < 3; ++c) info.toLight[c] = glm::vec4(o.toLight[c], 0.0f);
    HC_CHECK_EQ(o.pointLights.size(), lightCount);
    info.pointLights = static_cast<std::uint32_t>(lightCount);
    info.groundRadiance = glm::vec4(0.0f);  // the ground's: the light stage's
    for (std::size_t k = 0; k < lightCount; ++k) {
      const FusedPointLight& l = o.pointLights[k];
      PointLight& out = pointLightData[i * shared::kMaxPointLights + k];
      out.direction = glm::vec4(l.direction, 0.0f);
      out.power = glm::vec4(l.power[0], l.power[1], l.power[2], 0.0f);
    }
  }
  if (fused) pointLightUpload.write(pointLightData.data(), pointLightData.size() * sizeof(PointLight));
  objects.write(objectInfo.data(), objectInfo.size() * sizeof(ObjectInfo));
  uploadFrameUniforms(request, resolved);

  // ---- the samples to shade, their shadow rays, the pass, the image
  const std::size_t pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  const glm::vec3 eye(render::CameraRays(request.camera, request.width, request.height).origin());
  // Where the point lights are staged: their copy into device memory.
  const FrameStage lightStage{"light", [&](VkCommandBuffer cb) {
                                pointLightUpload.record(cb);
                                recordFusedLight(cb, resolved);
                              }};
  const FrameStage gbufferStage{"gbuffer", [&](VkCommandBuffer cb) { recordGBuffer(cb, resolved); }};
  const FrameStage rotationInputStage{"rotation-input", [&](VkCommandBuffer cb) {
                                        vkCmdFillBuffer(cb, counter.handle(), 0, VK_WHOLE_SIZE, 0u);
                                        if (fused) vkCmdFillBuffer(cb, sliceCounts.handle(), 0, VK_WHOLE_SIZE, 0u);
                                        computeBarrier(cb);
                                        rotationInput->dispatch(cb, {groupsOf(pixels, shared::kLocalSize), 1, 1});
                                        recordCounterCopy(cb);
                                      }};
  const FrameStage passStage{splitsum ? "splitsum" : "fused", [&](VkCommandBuffer cb) {
                               if (!deviceRays) {
                                 // Where the host's rays are staged: their copies into device memory.
                                 maskUpload.record(cb);
                                 if (objectSky()) hiddenUpload.record(cb);
                                 computeBarrier(cb);
                                 markPart(cb, "uploads");
                               }
                               if (!fused) {
                                 fusedPass->dispatchIndirect(cb, counter, offsetof(CoverageCounter, groups));
                               } else if (!(options.smoothSumTolerance > 0.0f)) {
                                 const shared::FusedPush push = fusedPush(shared::kSmoothSumOff, 0, 0.0f);
                                 fusedPass->dispatchIndirect(cb, counter, offsetof(CoverageCounter, groups), &push, sizeof push);
                               } else {
                                 recordSmoothStages(cb);
                               }
                               if (fused) {
                                 computeBarrier(cb);
                                 const VkBufferCopy counts{0, 0, sliceCounts.size()};
                                 vkCmdCopyBuffer(cb, sliceCounts.handle(), sliceCountsOut.handle(), 1, &counts);
                               }
                             }};
  const FrameStage tonemapStage{"tonemap", [&](VkCommandBuffer cb) { recordTonemap(cb, request); }};
  std::uint32_t covered = 0;
  // The stages up to the shadow rays (splitsum keeps no light of its own:
  // it turns its lookup, ObjectInfo::toLight), then the rest where the
  // device traces the rays.
  std::vector<FrameStage> stages;
  if (fused) stages.push_back(lightStage);
  stages.insert(stages.end(), {gbufferStage, rotationInputStage});
  if (deviceRays) {
    // One submission: the rays traced on the device between rotation-input and the pass.
    writeRays(resolved, eye);
    stages.insert(stages.end(), {{"shadow-rays", [&](VkCommandBuffer cb) { recordDeviceRays(cb); }}, passStage, tonemapStage});
    runStages(stages, request, frame);
    if (frame.cancelled) return frame;
    if (fused) fusedLightMade();
    covered = coveredSamples();
  } else {
    runStages(stages, request, frame);
    if (frame.cancelled) return frame;  // stopped between stages: no images
    if (fused) fusedLightMade();

    // ---- shadow-rays (host): each covered sample's point-light bits
    frame.cancelled = cancelRequested();
    if (frame.cancelled) return frame;
    const auto t0 = RendererClock::now();
    render::enterFrameStage(request, "shadow-rays");
    covered = computeShadowMasks(resolved, eye);
    frame.stages.push_back({"shadow-rays", secondsSince(t0)});
    runStages({passStage, tonemapStage}, request, frame);
    if (frame.cancelled) return frame;
  }

  // ---- Results: RGBA8 always, the linear image and mask only when asked for
  frame.rgba8.resize(pixels * 4);
  rgba8.read(frame.rgba8.data(), frame.rgba8.size());
  if (request.linearImage) readLinearImage(frame);
  finishExposure(request, frame);

  // Coefficient bytes read, counted as the CPU backend counts them: the
  // light, and per shaded sample core fusedPixelBytes (one slice or two, the
  // light planes, the three vertices' visibility words); the ground reads none.
  // The device counted each object's samples of one slice and of two.
  // splitsum: core splitsumPixelBytes per sample, the ground's too.
  std::size_t bytes = resolved.lightBytes;
  if (splitsum) {
    frame.coefficientBytes = bytes + covered * splitsumPixelBytes();
    frame.seconds = secondsSince(start);
    return frame;
  }
  constexpr std::size_t kWords = shared::kSliceCountsPerObject;
  std::vector<std::uint32_t> counts(kWords * objectCount);
  sliceCountsOut.read(counts.data(), counts.size() * sizeof(std::uint32_t));
  std::size_t counted = 0;
  for (std::size_t i = 0; i < objectCount; ++i) {
    const std::uint32_t* c = counts.data() + kWords * i;
    counted += std::size_t{c[0]} + c[1] + c[6];
    if (prepared.objects[i].ground) continue;
    const int objectLevel = prepared.objects[i].level;
    const std::size_t visibilityBytes = 3 * shared::visibilityWords(static_cast<shared::uint>(objectLevel)) * sizeof(std::uint32_t);
    bytes += c[0] * fusedPixelBytes(objectLevel, false, visibilityBytes) +
             c[1] * fusedPixelBytes(objectLevel, true, visibilityBytes);
    // The pass's directions: its rows × M (shared_layout.h passRows), or by
    // cells one per coarse cell and 16 per fine one (core FusedScratch::passDirections).
    const std::size_t m = static_cast<std::size_t>(mapSize(objectLevel));
    frame.passSamples += std::size_t{c[0]} + c[1] + c[6];  // those taken from their neighbours read no slice
    frame.passDirections += std::size_t{c[2]} * m + c[4] + shared::kCellDirections * std::size_t{c[5]};
    frame.passDirectionsMax = std::max(frame.passDirectionsMax, std::size_t{c[3]});
    frame.smoothSamples += c[6];
  }
  HC_CHECK_EQ(counted, std::size_t{covered});  // the pass shaded every covered sample once
  frame.coefficientBytes = bytes;
  frame.seconds = secondsSince(start);
  return frame;
}

}  // namespace haarcast::gpu
