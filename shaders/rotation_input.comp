#version 450
// The "rotation-input" pass: per covered pixel, what the rotation needs (the
// nearest θₒ slice and the Y-X-Y Euler angles of the local shading frame) and
// what the triple product needs (object, vertices, barycentrics). The same
// math as render::rotationInput: the shading frame and its Euler angles of
// core/shared_frame.h and the nearest slice of shared_layout.h's
// sliceBlendAt, in float. Covered pixels
// are compacted through an atomic counter, so their order is arbitrary;
// every record carries its radiance slot. Local size kLocalSize, one invocation per
// pixel.
//
// Antialiasing (frame.antialias, shared_layout.h): a pixel whose 3×3
// neighbourhood of centre ids is not one object (or all none; clamped at the
// frame's border, as the CPU backend) is an edge pixel. It emits no centre
// sample but one per covered sub-sample, read from the G-buffer rasterised
// at twice the resolution, and leaves which sub-samples it covered in
// `edges` for the resolve pass.
#extension GL_GOOGLE_include_directive : require
#include "common/frame.glsl"
#include "common/sphere.glsl"

layout(local_size_x = kLocalSize) in;

layout(std430, set = 0, binding = kRotationInputFrameBinding) readonly buffer Frame { FrameParams frame; };
layout(std430, set = 0, binding = kRotationInputObjectsBinding) readonly buffer Objects { ObjectInfo objects[]; };
layout(std430, set = 0, binding = kRotationInputIdsBinding) readonly buffer Ids { uvec4 ids[]; };          // G-buffer: object+1, triangle, b1, b2
layout(std430, set = 0, binding = kRotationInputNormalsBinding) readonly buffer Normals { vec4 normals[]; };    // G-buffer: object-frame normal
layout(std430, set = 0, binding = kRotationInputTrianglesBinding) readonly buffer Triangles { uint triangles[]; };  // global vertex ids, 3 per triangle
layout(std430, set = 0, binding = kRotationInputSamplesBinding) writeonly buffer Samples { RotationSample samples[]; };
layout(std430, set = 0, binding = kRotationInputShadeBinding) writeonly buffer Shade { ShadeSample shade[]; };
layout(std430, set = 0, binding = kRotationInputCounterBinding) buffer Counter { CoverageCounter counter; };
layout(std430, set = 0, binding = kRotationInputSubIdsBinding) readonly buffer SubIds { uvec4 subIds[]; };          // the 2× G-buffer
layout(std430, set = 0, binding = kRotationInputSubNormalsBinding) readonly buffer SubNormals { vec4 subNormals[]; };
layout(std430, set = 0, binding = kRotationInputEdgesBinding) writeonly buffer Edges { uint edges[]; };  // per pixel: 0, or kEdgeFlag | covered bits

// One shaded sample: G-buffer record `id` (object + 1, triangle, b1, b2),
// object-frame normal `normal`, camera ray `direction`, radiance to `slot`.
void emit(uvec4 id, vec3 normal, vec3 direction, uint slot) {
  ObjectInfo o = objects[id.x - 1u];
  vec3 n = normalize(normal);
  mat3 toWorld = mat3(o.rotation[0].xyz, o.rotation[1].xyz, o.rotation[2].xyz);
  vec3 wo = transpose(toWorld) * -direction;  // toward the eye, object frame

  float thetaOut;
  const vec3 euler = eulerYXYOf(shadingFrame(n, wo, thetaOut));  // (α, β, γ)

  // The nearest slice: BrdfSliceTable::nearestSlice in float.
  uint t = sliceBlendAt(thetaOut, o.thetaSamples, 0u).first;

  uint k = atomicAdd(counter.covered, 1u);
  // `fused`'s indirect dispatch: one workgroup per covered pixel, at most
  // frame.fusedGroups (each loops over the pixels beyond).
  if (k < frame.fusedGroups) {
    atomicMax(counter.groups[0], k + 1u);
    if (k == 0u) {
      atomicMax(counter.groups[1], 1u);
      atomicMax(counter.groups[2], 1u);
    }
  }
  samples[k] = RotationSample(o.sliceBase + t, o.methodBase, euler.x, euler.y, euler.z, slot, thetaOut, 0u);
  uint tri = o.triangleBase + id.y;
  float b1 = uintBitsToFloat(id.z), b2 = uintBitsToFloat(id.w);
  shade[k] = ShadeSample(id.x - 1u, uint[3](triangles[3u * tri], triangles[3u * tri + 1u], triangles[3u * tri + 2u]),
                         float[3](1.0 - b1 - b2, b1, b2), slot);
}

// The edge test of the CPU backend (cpu_backend.cpp traceGBuffer).
bool isEdge(uint x, uint y, uint mine) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      uint nx = uint(clamp(int(x) + dx, 0, int(frame.width) - 1));
      uint ny = uint(clamp(int(y) + dy, 0, int(frame.height) - 1));
      if (ids[ny * frame.width + nx].x != mine) return true;
    }
  }
  return false;
}

void main() {
  uint p = gl_GlobalInvocationID.x;
  uint pixels = frame.width * frame.height;
  if (p >= pixels) return;
  uint x = p % frame.width, y = p / frame.width;
  uvec4 id = ids[p];
  if (frame.antialias != 0u) {
    if (isEdge(x, y, id.x)) {
      uint covered = 0u;
      for (uint k = 0u; k < kSubsamples; ++k) {
        uint q = subsampleRasterIndex(frame.width, x, y, k);
        if (subIds[q].x == 0u) continue;  // the backdrop, drawn by the resolve pass
        emit(subIds[q], subNormals[q].xyz, subsampleDirection(frame, x, y, k), subsampleSlot(pixels, p, k));
        covered |= 1u << k;
      }
      edges[p] = kEdgeFlag | covered;
      return;
    }
    edges[p] = 0u;
  }
  if (id.x == 0u) return;  // background
  emit(id, normals[p].xyz, cameraDirection(frame, x, y), p);
}
