// The Vulkan passes' interface, shared by the host (server/gpu/src) and the
// shaders: workgroup sizes, push blocks and descriptor bindings. Part of
// shared_layout.h, which includes it inside its namespace with its macros:
// include that instead.
//
// A pass's bindings are those of set 0, 0 … k<Pass>Bindings − 1
// (gpu::ComputePipeline). The shaders declare each at its name here, and the
// host binds by the same names (ComputePipeline::bind of BindingAt) and sizes
// its set layouts by the counts, so a binding moved here moves on both sides.
#ifndef HAARCAST_CORE_SHARED_PASSES_H
#define HAARCAST_CORE_SHARED_PASSES_H

// ---- Workgroup sizes

// The local size of the per-pixel and per-batch passes (rotation_input,
// resolve, tonemap, triple_product, batch_args), which the host's group
// counts divide by; and the host's pick for the passes that take theirs as
// specialization constant kSpecLocalSize (rotate_*.comp; splitsum) on a CPU device.
HC_CONST uint kLocalSize = 64u;
// The host's pick for those passes and for `fused` on a GPU, and the
// default of the rotation shaders that declare one.
HC_CONST uint kGpuLocalSize = 256u;
// exposure.comp: workgroups of the least maxComputeWorkGroupInvocations
// Vulkan guarantees, each invocation metering about
// kExposurePixelsPerInvocation pixels (a 1920×1080 frame: 1013 workgroups,
// each adding its shared histograms' non-empty bins to the frame's once).
HC_CONST uint kExposureLocalSize = 128u;
HC_CONST uint kExposurePixelsPerInvocation = 16u;

// shadow_rays.rgen (shared_rays.h): storage buffers at these bindings, the
// top-level acceleration structure at kRaysSceneBinding.
HC_CONST uint kRaysShadeBinding = 0u;
HC_CONST uint kRaysCounterBinding = 1u;
HC_CONST uint kRaysPositionsBinding = 2u;
HC_CONST uint kRaysNormalsBinding = 3u;
HC_CONST uint kRaysObjectsBinding = 4u;
HC_CONST uint kRaysFrameBinding = 5u;
HC_CONST uint kRaysSkyLightBinding = 6u;
HC_CONST uint kRaysPixelSampleBinding = 7u;
HC_CONST uint kRaysGridBinding = 8u;
HC_CONST uint kRaysMasksBinding = 9u;
HC_CONST uint kRaysHiddenBinding = 10u;
HC_CONST uint kRaysSkyJobsBinding = 11u;      // uint count, then SkyJob[skyJobCapacity]
HC_CONST uint kRaysSkyPartialsBinding = 12u;  // float per job and lane
HC_CONST uint kRaysStageListsBinding = 13u;   // fused's stage lists (shared_smooth.h), read
HC_CONST uint kRaysSceneBinding = 14u;
HC_CONST uint kRaysStorageBindings = 14u;

// ---- Specialization constants: the ids the shaders declare them at
// (layout(constant_id = …)) and the host sets them by (gpu::SpecConstant).
HC_CONST uint kSpecLevel = 0u;            // LEVEL: the maps are 2^LEVEL × 2^LEVEL
HC_CONST uint kSpecThetaSamples = 1u;     // THETA_SAMPLES: slices per channel per object
HC_CONST uint kSpecLocalSize = 2u;        // local_size_x_id: the host's workgroup size
HC_CONST uint kSpecInterpolate = 4u;      // INTERPOLATE: RenderOptions::interpolateSlices
HC_CONST uint kSpecPrefilterFinest = 5u;  // PREFILTER_FINEST: the prefiltered light's finest level
// SUBGROUP_REDUCE (fused.comp): 1 when the workgroup is one subgroup (a CPU
// device's SIMD width) and the reduction is subgroupAdd, with no shared
// memory and no barrier; 0: shared memory and barriers (GPUs, whose
// workgroups span several subgroups). Mesa ≥ 24's lavapipe compiles a
// shader with barriers into LLVM coroutines, which took 126 s for fused.comp
// (docs/gpu.md, "Shader compilation on lavapipe").
HC_CONST uint kSpecSubgroupReduce = 6u;
// CELLS_TOGETHER (fused.comp, the sum by cells): 1 when the device's
// subgroups have ballot, shuffle and arithmetic in compute shaders: a
// subgroup takes its cells that need 16 directions one at a time, its lanes
// across the cell, instead of each lane its own while the others wait;
// 0: each invocation sums its own cells.
HC_CONST uint kSpecCellsTogether = 7u;

// ---- Indirect dispatch

// The rotation-input pass's counter, followed by the indirect dispatch
// arguments of `fused` (VkDispatchIndirectCommand at byte 4): groups[0] =
// min(covered, FrameParams::fusedGroups), groups[1] = groups[2] = 1 once
// any pixel is covered.
struct CoverageCounter {
  uint covered;
  uint groups[3];
};

// The rotating methods' batches, sized on the device: batch_args.comp
// writes, from the covered count, per batch b of `batch` samples with
// count_b = clamp(covered − b·batch, 0, batch), the rotation's arguments
// (count_b, 3, 1) at [b] and the triple product's (⌈3·count_b / kLocalSize⌉, 1, 1)
// at [batches + b] (VkDispatchIndirectCommand, padded to 16 bytes).
struct DispatchArgs {
  uint groups[3];
  uint pad;
};

// ---- Push blocks

// The rotation contract's push block (rotate_*.comp, triple_product.comp):
// the batch's samples first … first + count − 1 (global indices).
struct RotationPush {
  uint first;   // global index of the batch's first sample
  uint count;   // samples in a full batch (the last may hold fewer: the covered count decides)
  uint pad0;
  uint pad1;
};

// batch_args.comp's push block (DispatchArgs).
struct BatchArgsPush {
  uint batch;    // samples per batch
  uint batches;  // batches recorded (the most the resolution can need)
  uint pad0;
  uint pad1;
};

// The G-buffer pass's push block (gbuffer.vert / .frag).
struct GBufferPush {
  mat4 objectToClip;
  uint objectId;
  uint triangleBase;
  uint pad0;
  uint pad1;
};

// ---- Bindings of set 0, per pass (what each holds: the shader's comments)

// rotation_input.comp
HC_CONST uint kRotationInputFrameBinding = 0u;
HC_CONST uint kRotationInputObjectsBinding = 1u;
HC_CONST uint kRotationInputIdsBinding = 2u;
HC_CONST uint kRotationInputNormalsBinding = 3u;
HC_CONST uint kRotationInputTrianglesBinding = 4u;
HC_CONST uint kRotationInputSamplesBinding = 5u;
HC_CONST uint kRotationInputShadeBinding = 6u;
HC_CONST uint kRotationInputCounterBinding = 7u;
HC_CONST uint kRotationInputSubIdsBinding = 8u;
HC_CONST uint kRotationInputSubNormalsBinding = 9u;
HC_CONST uint kRotationInputEdgesBinding = 10u;
HC_CONST uint kRotationInputBindings = 11u;

// resolve.comp
HC_CONST uint kResolveFrameBinding = 0u;
HC_CONST uint kResolveIdsBinding = 1u;
HC_CONST uint kResolveRadianceBinding = 2u;
HC_CONST uint kResolveBackgroundBinding = 3u;
HC_CONST uint kResolveEdgesBinding = 4u;
HC_CONST uint kResolveBindings = 5u;

// exposure.comp (the histograms, many workgroups) and exposure_readout.comp
// (one invocation: the histograms read out into the result)
HC_CONST uint kExposureFrameBinding = 0u;
HC_CONST uint kExposureIdsBinding = 1u;
HC_CONST uint kExposureRadianceBinding = 2u;
HC_CONST uint kExposureResultBinding = 3u;
HC_CONST uint kExposureHistogramsBinding = 4u;
HC_CONST uint kExposureBindings = 5u;

// tonemap.comp
HC_CONST uint kTonemapFrameBinding = 0u;
HC_CONST uint kTonemapRadianceBinding = 1u;
HC_CONST uint kTonemapRgba8Binding = 2u;
HC_CONST uint kTonemapThresholdsBinding = 3u;
HC_CONST uint kTonemapExposureBinding = 4u;
HC_CONST uint kTonemapBindings = 5u;

// The rotation contract (rotate_common.glsl, rotate_spatial.comp).
HC_CONST uint kRotateSamplesBinding = 0u;
HC_CONST uint kRotateSlicesBinding = 1u;
HC_CONST uint kRotateMethodDataBinding = 2u;
HC_CONST uint kRotateRotatedBinding = 3u;
HC_CONST uint kRotateBindings = 4u;

// triple_product.comp
HC_CONST uint kTripleProductShadeBinding = 0u;
HC_CONST uint kTripleProductRotatedBinding = 1u;
HC_CONST uint kTripleProductLightBinding = 2u;
HC_CONST uint kTripleProductVisibilityBinding = 3u;
HC_CONST uint kTripleProductRadianceBinding = 4u;
HC_CONST uint kTripleProductCounterBinding = 5u;
HC_CONST uint kTripleProductBindings = 6u;

// batch_args.comp
HC_CONST uint kBatchArgsCounterBinding = 0u;
HC_CONST uint kBatchArgsArgsBinding = 1u;
HC_CONST uint kBatchArgsBindings = 2u;

// fused.comp; the *Texels bindings are uniform texel buffers, the rest
// storage buffers (gpu::fusedBindings).
HC_CONST uint kFusedSamplesBinding = 0u;
HC_CONST uint kFusedShadeBinding = 1u;
HC_CONST uint kFusedObjectsBinding = 2u;
HC_CONST uint kFusedSliceTexelsBinding = 3u;
HC_CONST uint kFusedLightTexelsBinding = 4u;
HC_CONST uint kFusedVisibilityTexelsBinding = 5u;
HC_CONST uint kFusedDirectionTexelsBinding = 6u;
HC_CONST uint kFusedPointLightsBinding = 7u;
HC_CONST uint kFusedRadianceBinding = 8u;
HC_CONST uint kFusedCounterBinding = 9u;
HC_CONST uint kFusedMasksBinding = 10u;
HC_CONST uint kFusedSliceEnergyBinding = 11u;
HC_CONST uint kFusedLobesBinding = 12u;
HC_CONST uint kFusedLobeLightTexelsBinding = 13u;
HC_CONST uint kFusedPointSliceTexelsBinding = 14u;
HC_CONST uint kFusedSliceCountsBinding = 15u;
// kFusedSliceCountsBinding's words per object: its samples of one slice (the
// ground's too) and of two, the pass's rows summed over its samples
// (passRows), the most directions for one sample, by cells
// (shared_cells.h) its coarse cells and its fine cells summed over them,
// and its samples whose sum came from their neighbours (shared_smooth.h).
HC_CONST uint kSliceCountsPerObject = 7u;
HC_CONST uint kFusedHiddenBinding = 16u;
HC_CONST uint kFusedDetailTexelsBinding = 17u;  // the slices' detail maps (shared_cells.h)
// The smooth sum's records, two vec4 per pixel (shared_smooth.h): the
// pixel's sum (rgb) and 1 + its object as the bits of w, 0 until it is
// visited; its mirror direction (xyz).
HC_CONST uint kFusedSmoothBinding = 18u;
HC_CONST uint kFusedStageListsBinding = 19u;  // the smooth sum's stage lists (shared_smooth.h)
HC_CONST uint kFusedBindings = 20u;

// fused.comp's push block: the smooth sum's stage this dispatch
// (shared_smooth.h; kSmoothSumOff: one dispatch shades every sample;
// kSmoothSumList: the stages' lists are written) and its part
// (kSmoothPartDecide, kSmoothPartSum), the frame's size, the tolerance, the
// most workgroups a stage's dispatch takes, and where the stages' lists of
// their own sums start (words past the stages' lists).
struct FusedPush {
  uint stage;
  uint width;
  uint height;
  float tolerance;
  uint groups;
  uint part;
  uint ownLists;
  uint pushPad;
};

// splitsum.comp; kSplitsumLobeLightTexelsBinding is a uniform texel
// buffer, the rest storage buffers (gpu::splitsumBindings).
HC_CONST uint kSplitsumSamplesBinding = 0u;
HC_CONST uint kSplitsumShadeBinding = 1u;
HC_CONST uint kSplitsumObjectsBinding = 2u;
HC_CONST uint kSplitsumCounterBinding = 3u;
HC_CONST uint kSplitsumMasksBinding = 4u;
HC_CONST uint kSplitsumLobesBinding = 5u;
HC_CONST uint kSplitsumLobeLightTexelsBinding = 6u;
HC_CONST uint kSplitsumRadianceBinding = 7u;
HC_CONST uint kSplitsumBindings = 8u;

// gbuffer.vert (vertex-stage storage buffers)
HC_CONST uint kGBufferPositionsBinding = 0u;
HC_CONST uint kGBufferNormalsBinding = 1u;
HC_CONST uint kGBufferTrianglesBinding = 2u;
HC_CONST uint kGBufferBindings = 3u;

#endif  // HAARCAST_CORE_SHARED_PASSES_H
