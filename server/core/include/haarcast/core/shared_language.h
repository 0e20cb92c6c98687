// The bridge that lets one header be compiled both as C++ and as GLSL: the
// shared headers (shared_layout.h, shared_frame.h, shared_display.h) write
// each number and small function once, and this header gives C++ the GLSL
// names they use and GLSL the qualifiers C++ needs.
//
// Write in the shared headers only what both languages read alike: plain
// structs of uint, float and vec3/vec4, `const` numbers, and functions built
// from floor/ceil/min/max/clamp, sqrt, log2, dot/cross/normalize, integer bit
// operations and findMSB. sin, cos, atan and acos are loose on a Vulkan
// device: a shared function that needs them calls HC_ACOS, HC_SIN, HC_ATAN2
// and the axis rotations rotX, rotY, which are std:: (and the templates
// below) in C++ and the precise ones of shaders/common/sphere.glsl in GLSL
// (the shader that calls such a function includes it).
//
// The HC_ macros stay defined after this header: every shared header uses
// them, and their prefix keeps them apart from everything else.
#ifndef HAARCAST_CORE_SHARED_LANGUAGE_H
#define HAARCAST_CORE_SHARED_LANGUAGE_H

#ifdef __cplusplus
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace haarcast::shared {
using uint = std::uint32_t;
using uvec2 = glm::uvec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using mat4 = glm::mat4;
using std::abs;
using std::ceil;
using std::clamp;
using std::exp2;
using std::floor;
using std::isinf;
using std::log2;
using std::max;
using std::min;
using std::sqrt;
// GLSL's findMSB: the index of the highest set bit, −1 for 0.
inline constexpr int findMSB(uint x) { return static_cast<int>(std::bit_width(x)) - 1; }
// GLSL's floatBitsToUint.
inline uint floatBitsToUint(float f) { return std::bit_cast<uint>(f); }
// R_y(a) adds a to φ: x̂ → (c, 0, −s), ẑ → (s, 0, c); R_x(b) tilts +Y toward
// +Z: ŷ → (0, c, s) (core/rotation.h; GLSL: common/sphere.glsl's).
template <class T>
inline glm::mat<3, 3, T> rotY(T a) {
  const T c = std::cos(a), s = std::sin(a);
  return glm::mat<3, 3, T>(glm::vec<3, T>(c, 0, -s), glm::vec<3, T>(0, 1, 0), glm::vec<3, T>(s, 0, c));
}
template <class T>
inline glm::mat<3, 3, T> rotX(T b) {
  const T c = std::cos(b), s = std::sin(b);
  return glm::mat<3, 3, T>(glm::vec<3, T>(1, 0, 0), glm::vec<3, T>(0, c, s), glm::vec<3, T>(0, -s, c));
}
}  // namespace haarcast::shared

#define HC_CONST inline constexpr
#define HC_FUNCTION inline
#define HC_CONSTEXPR inline constexpr
// GLSL's `precise`: no fused multiply-add, so the device rounds as the CPU
// (whose baseline x86-64 build has no FMA to contract into).
#define HC_PRECISE
#define HC_OUT(type) type&
#define HC_ACOS std::acos
#define HC_SIN std::sin
#define HC_ATAN2 std::atan2
// A function of the real type: a template over it in C++ (the CPU calls the
// double paths with double and the float kernels with float, and both round
// as written), float in GLSL. Write literals as HC_REAL(2).
#define HC_REAL_FUNCTION template <class HcReal> inline
#define HC_REAL HcReal
#define HC_VEC3 glm::vec<3, HcReal>
#define HC_MAT3 glm::mat<3, 3, HcReal>
#else
#define HC_CONST const
#define HC_FUNCTION
#define HC_CONSTEXPR
#define HC_PRECISE precise
#define HC_OUT(type) out type
#define HC_ACOS acosPrecise
#define HC_SIN sinPrecise
#define HC_ATAN2 atan2Precise
// common/sphere.glsl
float acosPrecise(float x);
float sinPrecise(float x);
float atan2Precise(float y, float x);
mat3 rotY(float a);
mat3 rotX(float b);
#define HC_REAL_FUNCTION
#define HC_REAL float
#define HC_VEC3 vec3
#define HC_MAT3 mat3
#endif

#endif  // HAARCAST_CORE_SHARED_LANGUAGE_H
