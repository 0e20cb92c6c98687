// A pixel's camera ray, its shading frame and the frame's Euler angles, one
// definition for the CPU (render::CameraRays, render::shadingFrame and
// eulerFromMatrix, in double, which the Monte Carlo reference shares
// exactly) and the shaders (common/frame.glsl, rotation_input.comp and
// rotate_table.comp, in float). Each function is a template over the real
// type in C++ and a float function in GLSL (HC_REAL_FUNCTION,
// shared_language.h); the two round alike because every operation is
// written once, in one order.
#ifndef HAARCAST_CORE_SHARED_FRAME_H
#define HAARCAST_CORE_SHARED_FRAME_H

#include "haarcast/core/shared_layout.h"

#ifdef __cplusplus
namespace haarcast::shared {
#endif

// A pinhole's ray through the point (px, py) of a width × height image, in
// pixels from its top-left corner (pixel (x, y)'s centre is (x + ½, y + ½),
// row 0 at the top): unit, in the frame of the camera's orthonormal basis
// (forward, right, up) with tanHalf = tan(½ vertical field of view) and
// aspect = width / height.
HC_REAL_FUNCTION HC_VEC3 cameraDirectionAt(HC_VEC3 forward, HC_VEC3 right, HC_VEC3 up, HC_REAL tanHalf,
                                           HC_REAL aspect, HC_REAL width, HC_REAL height, HC_REAL px, HC_REAL py) {
  const HC_REAL sx = (HC_REAL(2) * px / width - HC_REAL(1)) * tanHalf * aspect;
  const HC_REAL sy = (HC_REAL(1) - HC_REAL(2) * py / height) * tanHalf;
  return normalize(forward + sx * right + sy * up);
}

// One image-plane coordinate of sub-sample k of a pixel (kSubsamples,
// kSubsampleOffset): `pixel` is its column (axisBit 1u: + when k & 1) or its
// row (axisBit 2u: + when k & 2, downwards).
HC_REAL_FUNCTION HC_REAL subsampleCoordinate(uint pixel, uint k, uint axisBit) {
  const HC_REAL offset = HC_REAL(kSubsampleOffset);
  return HC_REAL(pixel) + HC_REAL(0.5) + ((k & axisBit) != 0u ? offset : -offset);
}

// The local frame of a shaded point as a rotation local → object, columns
// (x, n, z): +Y = the shading normal n (unit), the view direction wo (unit,
// toward the eye) in the (Y, Z) half-plane at φ = 0 (DESIGN.md "BRDF
// slices"), x = n × z (right-handed). thetaOut gets θₒ, clamped to [0, π/2].
HC_REAL_FUNCTION HC_MAT3 shadingFrame(HC_VEC3 n, HC_VEC3 wo, HC_OUT(HC_REAL) thetaOut) {
  const HC_REAL c = clamp(dot(n, wo), HC_REAL(-1), HC_REAL(1));
  thetaOut = HC_ACOS(max(c, HC_REAL(0)));
  HC_VEC3 z = wo - c * n;
  if (dot(z, z) < HC_REAL(1e-16)) {  // view along the normal: any tangent will do
    z = abs(n.x) < HC_REAL(0.9) ? cross(n, HC_VEC3(1, 0, 0)) : cross(n, HC_VEC3(0, 1, 0));
  }
  z = normalize(z);
  return HC_MAT3(cross(n, z), n, z);
}

// The Y-X-Y Euler angles (α, β, γ) of a rotation m = R_y(α) R_x(β) R_y(γ)
// (core/rotation.h eulerFromMatrix), β in [0, π]. m·ŷ = (sin β sin α, cos β,
// sin β cos α) is column 1 of m.
HC_REAL_FUNCTION HC_VEC3 eulerYXYOf(HC_MAT3 m) {
  const HC_VEC3 ny = m[1];
  const HC_REAL beta = HC_ACOS(clamp(ny.y, HC_REAL(-1), HC_REAL(1)));
  HC_REAL alpha;
  HC_REAL gamma;
  if (HC_SIN(beta) > HC_REAL(1e-12)) {
    alpha = HC_ATAN2(ny.x, ny.z);
    // R_y(γ) = R_x(β)ᵀ R_y(α)ᵀ m; its column 0 is (cos γ, 0, −sin γ).
    const HC_MAT3 ry = transpose(rotX(beta)) * transpose(rotY(alpha)) * m;
    gamma = HC_ATAN2(-ry[0][2], ry[0][0]);
  } else {
    // The gimbal pole. β = 0: m = R_y(α+γ). β = π: R_x(π)R_y(γ) =
    // R_y(−γ)R_x(π), so m = R_y(α−γ)R_x(π). Either way the whole turn goes
    // to α: m·x̂ = R_y(α)x̂.
    const HC_VEC3 nx = m[0];
    alpha = HC_ATAN2(-nx.z, nx.x);
    gamma = HC_REAL(0);
  }
  return HC_VEC3(alpha, beta, gamma);
}

#ifdef __cplusplus
}  // namespace haarcast::shared
#endif

#endif  // HAARCAST_CORE_SHARED_FRAME_H
