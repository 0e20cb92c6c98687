// `fused`'s sum from a pixel's neighbours (core/shared_smooth.h; the CPU's
// cpu_backend.cpp shadeSmoothSums): which samples the smooth sum visits
// (each in the stage smoothStageOf names: fused.comp listStages), and the
// sum a pixel takes from its parents. Included by fused.comp after what
// it reads: the push block and the shade, objects, radiance and smoothData
// bindings.
#ifndef HAARCAST_FUSED_SMOOTH_GLSL
#define HAARCAST_FUSED_SMOOTH_GLSL

// Whether sample s is the smooth sum's to visit (cpu_backend.cpp
// shadeSmoothSums): an interior pixel's centre sample on an object the pass
// sums (not the ground, not the lobe path alone).
bool smoothVisited(ShadeSample sh, ObjectInfo o) {
  return sh.pixel < push.width * push.height && (o.flags & kObjectGround) == 0u &&
         !((o.flags & kObjectLobePath) != 0u && o.lobeCore.x <= -1.0);
}
// A parent's sum and mirror, where it is on `object` and visited.
bool smoothParent(uint q, uint object, vec3 mirror, float cosLimit, out vec3 sum) {
  const vec4 a = smoothData[2u * q];
  sum = a.rgb;
  return floatBitsToUint(a.w) == object + 1u && smoothMirrorNear(mirror, smoothData[2u * q + 1u].xyz, cosLimit);
}
// The sum pixel `pixel` takes from its parents (cpu_backend.cpp
// shadeSmoothSums, in the same order), or false where it sums its own.
bool smoothTaken(ShadeSample sh, ObjectInfo o, vec3 mirror, out vec3 sum) {
  sum = vec3(0.0);
  if (push.stage == kSmoothSumOff || push.stage == 0u) return false;
  const int x = int(sh.pixel % push.width), y = int(sh.pixel / push.width);
  SmoothParents p = smoothParents(push.stage, x, y, int(push.width), int(push.height));
  if (p.count <= 0) return false;
  const float cosLimit = o.lobeCore.y;
  vec3 s0, s1, s2 = vec3(0.0), s3 = vec3(0.0), s4 = vec3(0.0), s5 = vec3(0.0), s6 = vec3(0.0), s7 = vec3(0.0);
  if (!smoothParent(p.at0, sh.object, mirror, cosLimit, s0) || !smoothParent(p.at1, sh.object, mirror, cosLimit, s1))
    return false;
  // The outer parents only measure the curve: on the object and visited
  // suffices (any mirror is near at a limit of −2).
  if (p.count == 4) {
    if (!smoothParent(p.at2, sh.object, mirror, cosLimit, s2) || !smoothParent(p.at3, sh.object, mirror, cosLimit, s3))
      return false;
    if (p.outer != 0u && !(smoothParent(p.at4, sh.object, mirror, -2.0, s4) && smoothParent(p.at5, sh.object, mirror, -2.0, s5) &&
                           smoothParent(p.at6, sh.object, mirror, -2.0, s6) && smoothParent(p.at7, sh.object, mirror, -2.0, s7)))
      p.outer = 0u;
  } else if (p.outer != 0u) {
    if (!smoothParent(p.at2, sh.object, mirror, -2.0, s2) || !smoothParent(p.at3, sh.object, mirror, -2.0, s3))
      p.outer = 0u;
  }
  const float brightness = smoothBrightness(p, radiance[p.at0].rgb, radiance[p.at1].rgb, radiance[p.at2].rgb,
                                            radiance[p.at3].rgb);
  if (!smoothSumsAgree(p, s0, s1, s2, s3, s4, s5, s6, s7, brightness, push.tolerance)) return false;
  sum = smoothParentsSum(p, s0, s1, s2, s3);
  return true;
}

#endif
