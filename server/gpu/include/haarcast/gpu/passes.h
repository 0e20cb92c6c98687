// Host mirrors of the records the Vulkan passes exchange (shaders/common/
// frame.glsl, the rotation contract), and the host-side packing they need.
// The renderer and the per-pass tests share these, so a test drives a
// shader with exactly the data the renderer gives it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec4.hpp>

#include "haarcast/core/haar.h"
#include "haarcast/render/scene.h"

namespace haarcast::gpu {

// The rotation contract's sample (32 bytes; rotate_*.comp binding 0).
struct RotationSample {
  std::uint32_t slice = 0;       // global slice: the object's slice base + θ slice
  std::uint32_t methodBase = 0;  // the object's offset into the method data, in words
  float alpha = 0, beta = 0, gamma = 0;
  std::uint32_t pixel = 0;
  std::uint32_t pad0 = 0, pad1 = 0;
};
static_assert(sizeof(RotationSample) == 32);

// What the triple product needs of a covered pixel (frame.glsl ShadeSample).
struct ShadeSample {
  std::uint32_t object = 0;
  std::uint32_t vertex[3] = {0, 0, 0};  // global vertex ids
  float b[3] = {0, 0, 0};               // barycentrics, b0 = 1 − u − v
  std::uint32_t pixel = 0;
};
static_assert(sizeof(ShadeSample) == 32);

// frame.glsl FrameParams (std430).
struct FrameParams {
  glm::vec4 forward{0}, right{0}, up{0};
  glm::vec4 lightRotT[3]{glm::vec4(0), glm::vec4(0), glm::vec4(0)};  // columns of lightRotationᵀ
  float tanHalf = 0, aspect = 0, gain = 1;
  std::uint32_t background = 0;
  std::uint32_t width = 0, height = 0, backgroundLevel = 0, pad = 0;
};
static_assert(sizeof(FrameParams) == 128);

// frame.glsl ObjectInfo (std430).
struct ObjectInfo {
  glm::vec4 rotation[3]{glm::vec4(0), glm::vec4(0), glm::vec4(0)};  // object → world, columns
  std::uint32_t sliceBase = 0, methodBase = 0, thetaSamples = 0, vertexBase = 0, triangleBase = 0;
  std::uint32_t pad[3] = {0, 0, 0};
};
static_assert(sizeof(ObjectInfo) == 80);

// The camera of render::CameraRays and the frame's settings.
FrameParams makeFrameParams(const render::Camera& camera, int width, int height, const glm::dmat3& lightRotation,
                            double exposureStops, bool background, int backgroundLevel);

// The tonemap pass's encoding table: [k] for k = 1 … 255 is the least linear
// value (before the gain 2^exposureStops) that io::writePng's sRGB encoding
// rounds to k or more, sRGB⁻¹((k − ½)/255) / gain, computed in double; [0] = 0.
std::array<float, 256> srgbThresholds(double exposureStops);

// Sparse Haar lists in the triple-product shader's form: one 16-byte block
// entry (preorder key, h, v, d bits) per block with a non-zero detail,
// sorted in the pre-order of core triple_product.cpp, and a header per list
// (first entry, entry count, scaling-coefficient bits, 0). Headers come
// first, in list order; entry offsets count from the start of the buffer.
// Throws std::invalid_argument when the lists' levels differ from `level`.
std::vector<glm::uvec4> packSparseLists(std::span<const SparseHaar> lists, int level);
// Entries (not headers) packSparseLists writes for one list.
std::size_t blockCount(const SparseHaar& list);
// The preorder key of triple_product.cpp: Morton code of the block's top-left
// finest block, shifted left by 4, | l.
std::uint32_t preorderKey(int mapLevel, int l, int i, int j);

// The level range of the GPU passes: shared memory holds one level-6 map
// (16 KiB) per workgroup, the least that Vulkan guarantees (and lavapipe's
// and NVIDIA's budgets allow with room for the method's scratch).
inline constexpr int kMinGpuLevel = 2;
inline constexpr int kMaxGpuLevel = 6;

}  // namespace haarcast::gpu
