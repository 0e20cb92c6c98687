// The one interface every backend implements, and that the server and the
// `render` / `bench-frame` commands drive: prepare a scene once (slice tables,
// rotators, visibility, GPU buffers), then render frame after frame with new
// camera, object and light poses.
//
// Stage names are shared by every backend so that timings line up in tables,
// in `bench-frame --json` and in the server's /metrics:
//   "light"           light rotated world → each object's frame, Haar-coded, cut to k
//   "gbuffer"         primary visibility: position, normal, object id, barycentrics
//   "rotation-input"  per pixel: BRDF slice index (θₒ) and Y-X-Y Euler angles
//   "rotation"        the rotated slice's coefficients, per pixel and channel
//   "triple-product"  light × rotated BRDF × interpolated vertex visibility
//   "shadow-rays"     `fused` and `splitsum` on Vulkan only: the host's point-light shadow rays for the
//                     device's samples, between its two submissions (the CPU's are in "fused")
//   "fused"           `fused` only: rotation and triple product in one pass
//                     over the map directions (core/fused.h), in place of the two above
//   "splitsum"        `splitsum` only: the lobe's energy times the prefiltered light
//                     along the mirror direction (core/splitsum.h), in place of the two
//                     above (the CPU's shadow rays are in it, as in "fused")
//   "tonemap"         exposure, sRGB, RGBA8 (and the linear image kept for EXR)
#pragma once

#include <algorithm>
#include <cstddef>
#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/mat3x3.hpp>

#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/fused.h"
#include "haarcast/core/haar.h"
#include "haarcast/core/light_split.h"
#include "haarcast/core/visibility_bits.h"
#include "haarcast/core/rotation.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/core/sphere_map.h"
#include "haarcast/io/image.h"
#include "haarcast/render/frame_stage.h"
#include "haarcast/render/render_options.h"
#include "haarcast/render/point_lights.h"
#include "haarcast/render/scene.h"
#include "haarcast/render/shading.h"
#include "haarcast/render/tonemap.h"

namespace haarcast::render {

struct FrameRequest {
  int width = 128;
  int height = 128;
  Camera camera;
  // One pose per scene object, in scene order; empty = the scene's own poses.
  std::vector<Pose> poses;
  // The environment turned by R: L'(ω) = L(Rᵀω). Identity = as loaded.
  glm::dmat3 lightRotation{1.0};
  // k, the light's largest coefficients kept; 0 = RenderOptions::lightCoefficients.
  std::size_t lightCoefficients = 0;
  // The RGBA8 image's exposure (tonemap.h): automatic by default.
  ExposureControl exposure;
  // The RGBA8 image's tone curve (tonemap.h).
  ToneCurve tone = ToneCurve::Reinhard;
  // false: the caller needs only rgba8 (an encoder), so a backend may skip
  // reading the linear image and the object mask back (Frame::image and
  // Frame::objectMask may then be empty).
  bool linearImage = true;
  // Polled at every tile (CPU: a row of a pass) or batch (Vulkan: a
  // submission) boundary; once it returns true the render stops there and
  // returns a Frame with `cancelled` set. Empty = never cancelled. Called on
  // the render's own threads, so it must be cheap and thread-safe.
  std::function<bool()> cancelled;
  // Where the frame is, for a watcher on another thread (frame_stage.h):
  // the backend enters each stage of the table above through
  // enterFrameStage(request, name). Null = nobody watches.
  StageMark* stage = nullptr;
};

struct StageTime {
  std::string name;      // one of the names above
  double seconds = 0.0;  // device time where the backend can measure it
};

struct Frame {
  int width = 0;                      // the request's size, whatever was read back
  int height = 0;
  io::RgbImage image;                 // linear radiance, for EXR and exact checks (empty if not requested)
  std::vector<std::uint8_t> rgba8;    // tonemapped, row 0 at the top, 4 bytes per pixel
  std::vector<std::uint8_t> objectMask;  // 1 where an object was hit (with the linear image; may be empty without)
  std::vector<StageTime> stages;      // in pipeline order
  // What a stage's time went to, where the backend marks it (Vulkan with
  // timestamps; the CPU backend's `fused` stage by the clock): "stage:
  // part", each from the mark before it in its stage, "stage: rest" to the
  // stage's end. For profiles (bench-frame --json); the stages above are the
  // frame's account.
  std::vector<StageTime> parts;
  double seconds = 0.0;               // wall time of render()
  std::size_t coefficientBytes = 0;   // coefficient data read this frame (slices, light, visibility, method tables)
  // `fused`: the object samples shaded (those the lobe path takes whole
  // count, with no directions), the map directions the pass visited over
  // all of them (its rows × M, core/shared_layout.h passRows) and the most
  // for one sample. What a sum over fewer directions brings down.
  std::size_t passSamples = 0;
  std::size_t passDirections = 0;
  std::size_t passDirectionsMax = 0;
  // Of passSamples, those whose sum came from their neighbours
  // (RenderOptions::smoothSumTolerance), with no directions.
  std::size_t smoothSamples = 0;
  double exposureStops = 0.0;         // the exposure rgba8 was made with
  double logAverageLuminance = 0.0;   // auto exposure's weighted log-average (exposure_meter.h); 0: none lit
  // The request's `cancelled` turned true mid-frame: the render stopped at
  // the next tile or batch boundary and the images are empty (an outcome,
  // not an error: nothing is wrong with the request).
  bool cancelled = false;
};

class Renderer {
 public:
  virtual ~Renderer() = default;
  virtual std::string backend() const = 0;     // "cpu" | "vulkan"
  virtual std::string deviceName() const = 0;  // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  virtual const RenderOptions& options() const = 0;
  // Where its frames' shadow rays are traced: "device" or "host"
  // (backend_names.h, RayMode), "none" for a method that traces none.
  virtual std::string rays() const { return "host"; }
  virtual std::size_t objectCount() const = 0;
  // Each object's map level (PreparedObject::level), in scene order; empty
  // where a renderer does not say.
  virtual std::vector<int> objectLevels() const { return {}; }
  // Each object's point-light slices' level (PreparedObject::pointLevel),
  // in scene order; empty where a renderer does not say.
  virtual std::vector<int> pointLightLevels() const { return {}; }
  // How each object's pixels are drawn (PreparedObject::plan, object_levels.h
  // describePlan), in scene order; empty where a renderer does not say.
  virtual std::vector<std::string> objectPlans() const { return {}; }
  // Whether render() may run on several threads at once. The CPU backend's
  // prepared data is immutable and each call keeps its own scratch, so it
  // may; a Vulkan renderer owns one set of device buffers per frame in
  // flight, and may when it has more than one (framesInFlight()).
  virtual bool concurrentRenders() const { return false; }
  // How many render() calls may run at once: 0 = any number, 1 = one at a
  // time (the server then makes the frames of the renderer's device take
  // turns), K = up to K (a caller past K waits inside render()).
  virtual std::size_t framesInFlight() const { return concurrentRenders() ? 0 : 1; }
  // One frame. Unless concurrentRenders(), one at a time per renderer.
  // Throws std::invalid_argument naming what was wrong (resolution outside
  // 1..8192, pose count ≠ object count, …).
  virtual Frame render(const FrameRequest& request) = 0;
};

// ---- What every backend shares: one definition of every number -----------

// Once per scene: what both backends upload or use, computed by the same code.
struct PreparedObject {
  std::string name;
  // Its map level: slices, visibility and, per frame, `fused`'s light
  // (RenderOptions::level, or with automaticLevel its own: object_levels.h).
  int level = 0;
  std::shared_ptr<const Mesh> mesh;    // with normals, object frame
  BrdfSliceTable table;                // unrotated slices: the only BRDF data kept
  // `fused` with point lights: the point lights' slices (core PixelSlices::
  // pointSlice) at pointLevel, finer than `level` where the lobe is narrow
  // (object_levels.h pointLightLevel); the same BRDF's unrotated slices.
  // Empty when pointLevel is `level`: the point lights read `table`.
  int pointLevel = 0;
  BrdfSliceTable pointTable;
  // What core PixelSlices::synthesize takes for the point slices: the finer
  // table, or null where `table` serves.
  const BrdfSliceTable* finerPointTable() const { return pointLevel != level ? &pointTable : nullptr; }
  // Per vertex, object frame: the Haar methods' top-k lists (empty for
  // fused), and fused's bits at map resolution (empty for the others).
  std::vector<SparseHaar> visibility;
  VisibilityBits visibilityBits;
  // `fused` by cells: each vertex's cell masks, from visibilityBits.
  CellVisibility cellVisibility;
  Pose pose;                           // the scene's pose
  bool ground = false;                 // the scene's ground (SceneObject::ground)
  // `fused`: RenderOptions::sumTolerance where the object is summed by cells
  // (shared_cells.h), else 0: the ground, shaded in closed form, and levels
  // below shared::kCellMinLevel. Both backends read it here, for the
  // slices' detail maps and the light's cells alike.
  float sumTolerance = 0.0f;
  glm::dvec3 groundAlbedo{0.0};        // its Lambert albedo
  float shadowShift = 0.0f;            // point-light rays' origin shift, object units (× pose scale)
  // A sphere around the mesh, object frame: its bounds' centre and the
  // farthest vertex from it (tighter than half the diagonal: the rays
  // toward an object's sphere, point_lights.h, hit it more often).
  glm::dvec3 sphereCentre{0.0};
  double sphereRadius = 0.0;
  // `fused`: its slices' lobes measured from the BRDF (core/lobe.h), and
  // whether any pixel of it can take the lobe path at the render's level
  // (then its samples trace a ray along their mirror direction too).
  // `splitsum`: the lobe of every θₒ sample (core/splitsum.h lobeThetaOut),
  // for every object, and lobePath always; its `table` is empty.
  std::vector<shared::SliceLobe> lobes;
  bool lobePath = false;
  float lobeCore = 0.0f;  // the lobe path's core angle (fused.h LobePath::coreAngle); π: the path takes all
  // `fused`: its sharpest slice's median lobe angle (core/lobe.h
  // sharpestMedian; π for the ground): how far a pixel's mirror direction
  // may be from its neighbours' for it to take their sum (core/shared_smooth.h).
  float sharpestLobe = 3.14159265f;
  // The object's plan as the log says it (object_levels.h describePlan).
  std::string plan;
};

struct ResolvedObject;

// `fused`: each object's last light in its frame (resolveFrame), kept while
// the light, the object and the ground have not turned. An orbiting camera,
// the most common interaction, then pays nothing for the light; a turned
// object or light misses and is resolved afresh. Shared by the copies of a
// PreparedScene, and safe to use from concurrent frames.
class FusedLightCache {
 public:
  struct Key {
    glm::dmat3 lightRotation{1.0};
    glm::dmat3 objectRotation{1.0};
    std::optional<glm::dvec3> groundNormal;
    bool operator==(const Key&) const = default;
  };
  // Copies the kept light of object `index` into `o` when it was resolved
  // for `key`; false otherwise.
  bool find(std::size_t index, const Key& key, ResolvedObject& o) const;
  void store(std::size_t index, const Key& key, const ResolvedObject& o);
  std::size_t hits() const { return hits_.load(); }

 private:
  struct Entry;
  mutable std::atomic<std::size_t> hits_{0};
  mutable std::mutex mutex_;
  std::vector<std::shared_ptr<const Entry>> entries_;  // by object index
};

struct PreparedScene {
  Scene scene;
  std::vector<PreparedObject> objects;
  std::array<SphereMap, 3> light;       // world frame, level n, radiance (no solid angle)
  std::array<SphereMap, 3> background;  // world frame, level kBackgroundLevel, for the backdrop
  // `fused` only: the light split (core/light_split.h) in the environment's
  // frame: its point lights, and the map without them at each object's
  // level and at the level each is turned from (lightTurnLevel), each the
  // solid-angle mean of the backdrop's rest (restLightAt).
  std::vector<DirectionalLight> pointLights;
  std::vector<std::array<SphereMap, 3>> restLight;  // [level] 0 … kBackgroundLevel: empty where not needed
  SphereMap restLuminance;              // the rest at kSkyRaysLevel, Rec. 709 luminance (the hidden sky's rays, point_lights.h)
  // The rest at a level some object uses or is turned from; throws
  // std::out_of_range otherwise.
  const std::array<SphereMap, 3>& restLightAt(int level) const;
  // The objects besides the ground: with two or more, `fused` lets them hide
  // sky from each other (point_lights.h SkyOccluders::objectSky).
  std::size_t standingObjects() const { return objects.size() - (ground ? 1 : 0); }
  // Each object's level, in scene order (PreparedObject::level).
  std::vector<int> objectLevels() const;
  std::vector<int> pointLightLevels() const;  // PreparedObject::pointLevel, in scene order
  std::vector<std::string> objectPlans() const;  // PreparedObject::plan, in scene order
  PrefilteredLight lobeLight;           // `fused`, `splitsum`: the backdrop's maps at every level, for the lobe path (empty when no object has one)
  std::optional<std::size_t> ground;    // index of the ground object, if any
  std::shared_ptr<FusedLightCache> fusedLightCache = std::make_shared<FusedLightCache>();
};

// Level of the backdrop maps: fine enough to look like the probe (512²).
inline constexpr int kBackgroundLevel = 9;
// The level of the map light the hidden sky's rays read (point_lights.h
// SkyOccluders): one for every scene, so that what an object's neighbours
// hide from it does not depend on the levels the others are drawn at.
inline constexpr int kSkyRaysLevel = 6;

// `fused`: the level an object's light is turned into its frame at, then
// averaged down to the object's by solid angle (core rotateSpatialMapsDown:
// turned at the object's own level, a coarse map's bilinear lookups lost or
// gained up to 6 % of the light). Two levels finer, but not past 7 (unless
// the object's is): a Lambert torus at level 6 measured 0.54 % relative L2
// turned from level 7 and 0.49 % from 8, which costs 4× as much each frame
// (docs/evaluation.md, "A level per object").
inline constexpr int kLightTurnFinest = 7;
inline int lightTurnLevel(int level) { return std::max(level, std::min(level + 2, kLightTurnFinest)); }

// One object's slice table at options.level (or at `level`), from
// options.cacheDir when cached there; progress as stage "slices NAME" (or
// "STAGE NAME": prepareScene's point tables are "point slices NAME").
// prepareScene uses it, and so does whatever sizes the tables without
// preparing the rest (loadtest).
BrdfSliceTable objectSliceTable(const SceneObject& object, const RenderOptions& options,
                                const RenderProgress& progress = {});
BrdfSliceTable objectSliceTable(const SceneObject& object, const RenderOptions& options, int level,
                                const RenderProgress& progress = {}, std::string_view stage = "slices");

// Slice tables (cached in options.cacheDir), visibility (cached), light and
// backdrop maps. Validates the scene's meshes; progress per long stage.
PreparedScene prepareScene(const Scene& scene, const RenderOptions& options, const RenderProgress& progress = {});

// The frame's light in one object's frame, solid angle folded in, Haar-coded
// and cut to its k largest coefficients (per channel):
// L_obj(ω) = L(lightRotationᵀ · objectRotation · ω).
std::array<SparseHaar, 3> lightInObjectFrame(const std::array<SphereMap, 3>& worldLight, const glm::dmat3& objectRotation,
                                             const glm::dmat3& lightRotation, std::size_t k);

// Per pixel, what the rotation needs: the nearest θₒ slice and the Y-X-Y
// angles of the local shading frame (n and wo in the object frame); θₒ itself
// for `fused`, which may blend the two nearest slices (shared::sliceBlendAt).
struct RotationInput {
  int slice = 0;
  EulerYXY euler;
  double thetaOut = 0.0;
};
RotationInput rotationInput(const glm::dvec3& normal, const glm::dvec3& towardEye, const BrdfSliceTable& table);
// The same without a table (slice 0), for `splitsum`, which keeps none.
RotationInput rotationInput(const glm::dvec3& normal, const glm::dvec3& towardEye);

// The backdrop seen along a world direction when the environment is turned
// by lightRotation (`toEnvironment` is lightRotationᵀ): bilinear in the maps
// (shared::latLongTaps, sphere_map.h's bilinearTaps in float), in float as
// the device's resolve pass takes it.
glm::vec3 backdropRadiance(const std::array<SphereMap, 3>& background, const glm::mat3& toEnvironment, const glm::vec3& direction);

// Throws std::invalid_argument naming the problem.
void checkFrameRequest(const FrameRequest& request, std::size_t objectCount);


// One frame resolved once, for every backend: the request checked, and per
// object its pose in effect, the light in its frame (cut to k) and, for
// `fused`, that light in pixel form (synthesised once per object per frame).
//
// `fused` gets the light whole instead: the map without its point lights
// (in pixel form, ΔΩ folded in; where the scene has a ground, zero below
// its plane for every other object, which the ground hides), and per object
// the point lights in its frame. A ground object's point-light powers are
// the radiance each adds where seen, and groundFlat the radiance of the map
// part (both in closed form for its Lambert plane). `splitsum` gets only the
// poses and toLight: it turns its lookup direction, not the light.
struct ResolvedObject {
  glm::dmat3 rotation{1.0};        // object → world
  glm::dmat4 objectToWorld{1.0};
  double scale = 1.0;
  std::array<SparseHaar, 3> light; // the Haar methods' (empty for fused)
  FusedLight fusedLight;           // empty unless the method is fused
  std::vector<FusedPointLight> pointLights;
  std::array<float, 3> groundFlat{};
  glm::mat3 toLight{1.0f};         // fused, splitsum: object frame → the environment's (lightRotationᵀ·rotation)
};
struct ResolvedFrame {
  CameraBasis camera{};               // the request's camera (cameraBasis)
  // World → clip for a rasteriser (shading.h viewProjection), the near plane
  // half the distance to the nearest posed object's bounding sphere.
  glm::dmat4 viewProjection{1.0};
  std::size_t lightCoefficients = 0;  // k in effect (the Haar methods)
  std::vector<ResolvedObject> objects;
  std::size_t lightBytes = 0;         // the light lists, index + value per entry; fused: its planes' floats
  std::vector<glm::vec3> pointLightDirections;  // fused: world frame, unit, toward each light
  // The environment's frame → the world this frame (lightRotationOf): what
  // every pass that reads the light or the backdrop turns by.
  glm::dmat3 lightRotation{1.0};
  SkyOccluders skyOccluders;          // fused with a ground or two objects: what their samples' hidden-sky rays need (point_lights.h)
};
// Where `fused`'s map light is made each frame: by resolveFrame on the host
// (the CPU backend), or on the device (the Vulkan backend's "light" stage,
// shaders/light.comp, from the same rest maps): then resolveFrame leaves
// each ResolvedObject's fusedLight empty and groundFlat zero, and resolves
// only what is one number per object or light (poses, point lights).
enum class FusedMapLight { Host, Device };
ResolvedFrame resolveFrame(const PreparedScene& prepared, const RenderOptions& options, const FrameRequest& request,
                           FusedMapLight mapLight = FusedMapLight::Host);
// The light's turn this frame: the request's (the wire's light pose) on top
// of the scene's own (Environment::rotation, a scene file's
// "environment": {"rotate": …}).
glm::dmat3 lightRotationOf(const PreparedScene& prepared, const FrameRequest& request);

}  // namespace haarcast::render
