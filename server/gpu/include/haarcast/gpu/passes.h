// The records the Vulkan passes exchange (core/shared_layout.h) and the
// host-side packing they need.
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

#include "haarcast/core/fused_cells.h"
#include "haarcast/core/haar.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/gpu/compute.h"
#include "haarcast/render/scene.h"
#include "haarcast/render/shading.h"

namespace haarcast::gpu {

// The records the passes exchange, defined once for C++ and GLSL
// (core/shared_layout.h, with their size and offset checks).
using shared::CoverageCounter;
using shared::DispatchArgs;
using shared::ExposurePush;
using shared::ExposureResult;
using shared::FrameParams;
using shared::GBufferPush;
using shared::HiddenLight;
using shared::LightPush;
using shared::ObjectInfo;
using shared::PointLight;
using shared::RayFrame;
using shared::RayObject;
using shared::RaysPush;
using shared::RotationSample;
using shared::ShadeSample;

// The camera of render::CameraRays (its basis from render::cameraBasis, as
// the G-buffer's projection) and the frame's settings. The exposure is not
// among them: it travels in the tonemap pass's thresholds.
FrameParams makeFrameParams(const render::Camera& camera, int width, int height, const glm::dmat3& lightRotation,
                            bool background, int backgroundLevel);
// The same from the basis a resolved frame carries (render::ResolvedFrame::camera).
FrameParams makeFrameParams(const render::CameraBasis& basis, int width, int height, const glm::dmat3& lightRotation,
                            bool background, int backgroundLevel);


// Sparse Haar lists in the triple-product shader's form: one 16-byte block
// entry (preorder key, h, v, d bits) per block with a non-zero detail,
// sorted by shared::haarPreorderKey (the walk's order, as on the CPU), and a
// header per list (first entry, entry count, scaling-coefficient bits, 0).
// Headers come first, in list order; entry offsets count from the start of
// the buffer.
// Throws std::invalid_argument when the lists' levels differ from `level`.
std::vector<glm::uvec4> packSparseLists(std::span<const SparseHaar> lists, int level);
// Entries (not headers) packSparseLists writes for one list.
std::size_t blockCount(const SparseHaar& list);

// fused.comp's directions: the unit vectors of a level's pixel centres, row
// by row (w: the pixel's solid angle), computed in double as core fused's
// and rounded to float.
std::vector<glm::vec4> pixelCentreDirections(int level);

// The directions of several levels in one table, for objects at their own
// levels (ObjectInfo::directionBase): each level's pixelCentreDirections
// once, ascending; level l's direction 0 at base[l] (0 for levels not in it),
// at levels ≥ 5 followed by its cells' centres (shared::cellCentreTexel).
struct DirectionTable {
  std::vector<glm::vec4> directions;
  std::array<std::uint32_t, shared::kFusedMaxLevel + 1> base{};
};
DirectionTable pixelCentreDirections(std::span<const int> levels);

// The kinds of fused.comp's and splitsum.comp's bindings, from their names
// (core/shared_passes.h): the *TexelsBinding ones uniform texel buffers
// (fused: RGBA32F slices, light, directions, prefiltered light, point
// slices; R32UI visibility words; R32F detail maps), the rest storage buffers.
std::vector<BindingKind> fusedBindings();
std::vector<BindingKind> splitsumBindings();

// The light of one object as fused.comp reads it: texel k = (L_r, L_g, L_b, 0)
// at direction k, from the three planes of core FusedLight (ΔΩ folded in),
// written to out[0 … N). A frame's light is light.comp's (fused_light.cpp);
// this is how a test hands fused.comp the host's instead.
void fusedLightTexels(std::span<const float> planes, std::span<glm::vec4> out);

// ObjectInfo's skipBelowY for fused.comp, from the slices' last non-zero row
// (core PixelSlices::lastNonZeroRow): directions whose rotated cos θ' is
// below it read only zero texels (fusedShade's cut).
void setFusedSkip(ObjectInfo& info, int level, int lastNonZeroRow);

// The level range of the GPU passes: shared memory holds one level-6 map
// (16 KiB) per workgroup, the least that Vulkan guarantees (and lavapipe's
// and NVIDIA's budgets allow with room for the method's scratch).
inline constexpr int kMinGpuLevel = static_cast<int>(shared::kMinLevel);
inline constexpr int kMaxGpuLevel = static_cast<int>(shared::kRotationMaxLevel);

}  // namespace haarcast::gpu
