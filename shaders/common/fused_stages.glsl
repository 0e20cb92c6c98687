// `fused`'s smooth-sum stages on the device (core/shared_smooth.h): the
// dispatch that lists every covered sample under its stage, and each
// stage's first dispatch, which decides an invocation a sample and lists
// the samples that sum their own for its second. Included by fused.comp
// after shadePixel and the bindings it reads (shade, objects, masks,
// stageLists, the push block).
#ifndef HAARCAST_FUSED_STAGES_GLSL
#define HAARCAST_FUSED_STAGES_GLSL

// Each covered sample into its stage's list, an invocation a sample: stage
// 0 takes every sample the smooth sum does not visit but the ground's,
// which are shaded here, an invocation each, rather than a workgroup each.
// A stage's deciding dispatch then takes ⌈count / LOCAL⌉ workgroups (at
// most push.groups).
void listStages() {
  const uint count = counter.covered;
  for (uint s = gl_GlobalInvocationID.x; s < count; s += gl_NumWorkGroups.x * LOCAL) {
    const ShadeSample sh = shade[s];
    const ObjectInfo o = objects[sh.object];
    if ((o.flags & kObjectGround) != 0u) {
      shadeGround(sh, o, masks[s]);
      continue;
    }
    const uint stage = smoothVisited(sh, o)
                           ? smoothStageOf(int(sh.pixel % push.width), int(sh.pixel / push.width), int(push.width), int(push.height))
                           : 0u;
    const uint i = atomicAdd(stageLists[stage], 1u);
    stageLists[stageLists[kSmoothListOffsets + stage] + i] = s;
    if (i % LOCAL == 0u && i / LOCAL < push.groups) atomicMax(stageLists[kSmoothDecideArgs + 4u * stage], i / LOCAL + 1u);
  }
}

// A stage's samples, an invocation each: those that take their parents'
// sum (or need none) shaded, the rest into the stage's list of its own
// sums, whose dispatch takes a workgroup a sample (at most push.groups).
void decideStage() {
  const uint count = stageLists[push.stage], first = stageLists[kSmoothListOffsets + push.stage];
  for (uint i = gl_GlobalInvocationID.x; i < count; i += gl_NumWorkGroups.x * LOCAL) {
    const uint s = stageLists[first + i];
    if (shadePixel(s, kPixelDecide)) continue;
    const uint j = atomicAdd(stageLists[kSmoothSumCounts + push.stage], 1u);
    stageLists[push.ownLists + first + j] = s;
    if (j < push.groups) atomicMax(stageLists[kSmoothSumArgs + 4u * push.stage], j + 1u);
  }
}

#endif
