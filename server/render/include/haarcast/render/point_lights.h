// The per-pixel half of `fused`'s light split (core/light_split.h): which of
// the point lights a shading point sees, by one shadow ray each against the
// whole posed scene — every object and the ground — so shadows between
// objects, on the ground and from a light's exact direction come from the
// same rays, and move with the objects in the frame they move.
//
// Both backends call pointLightMask with the same inputs (the hit triangle,
// its barycentrics as float, the object's pose), so the CPU and the Vulkan
// backend (which reads its rasterised G-buffer's samples back for it) give
// the same bits.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "haarcast/core/fused.h"
#include "haarcast/core/mesh.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/render/embree_scene.h"

namespace haarcast::render {

// Where a sample's shadow rays start, in the world frame: the point on the
// hit triangle, and the unit shading normal (the barycentric blend of the
// vertex normals), and the origin's shift along it.
struct ShadingPoint {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 1.0f, 0.0f};
  float shift = 0.0f;
};

// The shift is VisibilityOptions::offset × the mesh's bounding radius × the
// pose's scale: the rule of the per-vertex visibility and of the Monte Carlo
// reference (reference.h), in world units.
// `rotation` is the pose's (object → world; poses scale uniformly).
ShadingPoint shadingPoint(const Mesh& mesh, const glm::uvec3& triangle, const float b[3], const glm::mat4& objectToWorld,
                          const glm::mat3& rotation, float shift);

// Bit k set when the point sees direction k (world frame, unit): n·d_k > 0
// and the ray from position + shift·n toward d_k escapes. At most 32 directions.
std::uint32_t pointLightMask(const RayScene& world, const ShadingPoint& p, std::span<const glm::vec3> directions);
// What can block a ground point's light: the ground is a plane, and a ray
// leaving it upward (n·d > 0) cannot come back to it, so only the objects
// can, each inside its bounding sphere (SkyOccluders::occluders). A ray that
// misses every sphere escapes, and needs no trace; on the open ground of a
// frame that is most of them.
struct GroundRays {
  std::span<const glm::vec4> blockers;     // world bounding spheres (centre, radius) of every object but the ground
  std::span<const std::uint8_t> onGround;  // per point: 1 on the ground (empty: none is)
};
// Bit k set when the ray origin + t·directions[k], t > 0, misses every
// sphere: a conservative test (each radius widened by 10⁻³ of itself for the
// float rounding), so a ray it lets through would have met nothing inside
// them. At most 32 directions.
std::uint32_t raysMissingSpheres(const glm::vec3& origin, std::span<const glm::vec3> directions,
                                 std::span<const glm::vec4> spheres);
// pointLightMask of many points at once, the same bits: each light's rays
// in packets of 16 neighbouring points (RayScene::occludedToward), which
// share their traversal; a ground point's ray that misses `ground`'s
// blockers is not traced. masks[i] is points[i]'s.
void pointLightMasks(const RayScene& world, std::span<const ShadingPoint> points, std::span<const glm::vec3> directions,
                     std::span<std::uint32_t> masks, const GroundRays& ground = {});

// shared::kLobeSeenBit when the ray from the point along the mirror
// direction of the eye escapes (the lobe path's visibility, fused.h: a lobe
// narrower than the visibility's texels sees along one direction), else 0.
std::uint32_t lobeRayBit(const RayScene& world, const ShadingPoint& p, const glm::vec3& eye);

// What the objects hide of the map light (the sky less its point lights)
// from the ground and from each other. The ground is shaded in closed
// form, the same at every point, and an object's map part meets its own
// visibility only, so without this an object standing on the ground casts
// no contact shadow from the sky, and objects side by side do not darken
// each other. Per sample, rays go toward each other object's bounding
// sphere — a cone of (2m) × (8m) stratified directions, m from 1 for a
// narrow cone to 4 for the hemisphere of a point beside the object
// (shared_rays.h groundSkyScale; 1 for an object's own pixels), the
// same pattern at every sample so the result is smooth and steady from
// frame to frame — against the whole posed scene. Objects whose cone can
// hide less than `minShare` of the sky are skipped (and faded in above it,
// so no edge shows), so rays go only near the objects.
struct SkyOccluders {
  std::vector<glm::vec4> occluders;  // world bounding spheres of the objects other than the ground (centre, radius)
  std::vector<std::uint32_t> objects;  // occluders[k]'s object index
  const SphereMap* luminance = nullptr;  // the map light's luminance, environment frame (PreparedScene::restLuminance)
  const std::array<SphereMap, 3>* colour = nullptr;  // the map light itself (rgb) at that level, environment frame
  glm::mat3 toEnvironment{1.0f};     // world → environment (lightRotationᵀ)
  bool ground = false;               // the scene has a ground: it hides what lies below its plane
  glm::vec3 normal{0.0f, 1.0f, 0.0f};  // the ground's, world
  double total = 0.0;                // Σ luminance·cos·ΔΩ over the ground's upper hemisphere
  double minShare = 0.03;  // faded in up to twice this
  bool objectSky = false;  // the objects' own hidden sky is computed (two objects or more besides the ground)
};
inline constexpr int kGroundSkyRings = static_cast<int>(shared::kGroundSkyRings);  // the device's too (shared_rays.h)
inline constexpr int kGroundSkySectors = static_cast<int>(shared::kGroundSkySectors);

// The share in [0, 1] of the ground's map light that the scene hides from p.
float groundSkyOcclusion(const RayScene& world, const ShadingPoint& p, const SkyOccluders& sky);

// The sky the other objects hide from p on object `object` (shared_rays.h
// HiddenLight): of each cone ray above p's horizon and above the ground's
// plane, the ones another object blocks and `object` itself does not (what
// it hides from itself is its visibility bits already; what lies below the
// ground's plane the ground hides from it already). `direction` is world
// frame; power 0 when nothing is hidden.
struct SkyHidden {
  glm::vec3 direction{0.0f, 1.0f, 0.0f};
  glm::vec3 power{0.0f};
};
SkyHidden objectSkyHidden(const RayScene& world, const ShadingPoint& p, std::size_t object, const SkyOccluders& sky);
// The same, packed for `fused` with its direction in the object's frame
// (`rotation`: the object's pose, object → world).
shared::HiddenLight hiddenLightOf(const SkyHidden& hidden, const glm::mat3& rotation);
// What `fused` takes off for it (core/fused.h fusedShade's `hidden`), or
// nullopt when nothing is hidden.
std::optional<std::array<float, 3>> hiddenIrradiance(const shared::HiddenLight& hidden);

// groundSkyOcclusion on a coarse grid of the frame, the pixels (i·step, j·step)
// and the last row and column, then for every ground sample the bilinear
// blend of its cell's corners when all four are ground. A cell an object's
// outline crosses (a corner off the ground) is refined: read from a grid
// groundSkyFineStep apart (shared_rays.h), whose points are traced only in
// such cells; there too the blend of a fine cell whose four corners are
// ground, else the sample's own rays. The hidden sky changes slowly over
// the open ground, and rays at every pixel would cost most of a frame.
// (Blending a crossed cell's other corners reached past the outline, away
// from where the object meets the ground, and left a too-bright halo around
// its foot. Every sample of a crossed coarse cell taking its own rays,
// 16 pixels wide at 720p, cost 40,000 samples' rays a frame on the default
// scene, and showed arcs where the pattern's size steps; the fine grid
// takes a sixth of that.) Both backends fill both grids from the same
// samples (interior pixels' centres) and blend alike.
// The grid's spacing: a 40th of the frame's larger side, 4 to 16 pixels (a
// contact shadow spans a share of the frame, not a number of pixels).
int groundSkyStep(int width, int height);

// The antialiasing's interior rule (shared_layout.h): pixel and its 3×3
// neighbours (clamped at the frame's border) all `ground`.
bool interiorPixel(std::size_t pixel, std::size_t width, std::size_t height, const std::function<bool(std::size_t)>& ground);
class GroundSkyGrid {
 public:
  GroundSkyGrid(int width, int height);
  // point(pixel) is the ground's shading point at that interior pixel's
  // centre, or nullopt (not the ground, an edge pixel, nothing).
  void compute(const RayScene& world, const SkyOccluders& sky,
               const std::function<std::optional<ShadingPoint>(std::size_t pixel)>& point, unsigned threads);
  // The occlusion for a ground sample of pixel y·width + x: the grids'
  // blend, or direct() (the sample's own rays) where neither covers it.
  // A template, so the call per ground sample wraps nothing on the heap.
  template <class Direct>
  float at(std::size_t pixel, const Direct& direct) const {
    const std::optional<float> v = blended(pixel);
    return v ? *v : direct();
  }
  // The grids' blend alone (nullopt: the sample's own rays are needed).
  std::optional<float> blended(std::size_t pixel) const;
  // Fine grid points traced by the last compute (what the refinement costs).
  std::size_t finePointsTraced() const { return fineTraced_; }

 private:
  int width_, height_, step_, columns_, rows_;
  int fineStep_, fineColumns_, fineRows_;
  std::vector<float> value_;  // per grid point; < 0 where it is not the ground
  std::vector<float> fine_;   // per fine grid point; < 0 off the ground or where no crossed cell needs it
  std::size_t fineTraced_ = 0;
  bool crossed(int i, int j) const;  // a corner of coarse cell (i, j) is off the ground
  bool fineNeeded(int k, int l) const;
};

// A ground sample's word: its light bits and the occlusion above them
// (shared_layout.h, kGroundOcclusionShift).
std::uint32_t withGroundOcclusion(std::uint32_t lightBits, float occlusion);

}  // namespace haarcast::render
