// What a frame shows: an environment, objects (mesh, material, pose) and a
// camera — from a small JSON scene file or built in.
//
// Scene file (paths relative to the file's folder; every key but "objects"
// optional):
//   {
//     "environment": {"file": "probes/grace_latlong.exr", "layout": "auto"},   // or {"builtin": "sky"|"suns"}
//     "camera": {"eye": [0, 0.4, 3.2], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y": 35},
//     "objects": [
//       {"name": "bunny", "mesh": "meshes/bunny.ply",            // or {"builtin": "sphere"|"torus"|"box"|"plane"}
//        "material": "brdfs/alum-bronze-sgd.binary",              // or "lambert", "phong:64", "blinn-phong:100", "ggx:0.25"
//        "rotate": [0, 30, 0], "translate": [0, 0, 0], "scale": 1.0,
//        "fit": true}                                             // centre and scale the mesh to unit radius first
//     ]
//   }
// "rotate" is in degrees about X, then Y, then Z (R = R_z R_y R_x).
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "haarcast/core/brdf.h"
#include "haarcast/core/mesh.h"
#include "haarcast/core/sphere_map.h"

namespace haarcast::render {

struct Pose {
  glm::dvec3 rotateDegrees{0.0};
  glm::dvec3 translate{0.0};
  double scale = 1.0;

  glm::dmat3 rotation() const;  // R = R_z R_y R_x
  glm::dmat4 objectToWorld() const;
};

// Radiance arriving from the world, two ways: per direction (background,
// Monte Carlo) and as area-averaged level-n maps (the Haar pipeline).
// `rotation` turns the environment's own frame into the world (a scene
// file's "environment": {"rotate": [x, y, z]}, the convention of a pose and
// of the wire's light_rotate_degrees): `radiance` is per world direction,
// already turned (L(ω) = L_env(Rᵀω)); the `maps` stay in the environment's
// own frame and the renderers turn them, composed with the request's light
// rotation (render::lightRotationOf).
struct Environment {
  std::string name;
  std::function<glm::dvec3(const glm::dvec3&)> radiance;
  std::function<std::array<SphereMap, 3>(int level)> maps;
  glm::dmat3 rotation{1.0};
};
// The environment turned by `rotation` on top of any turn it has: its
// radiance per world direction follows, its maps keep their own frame.
void rotateEnvironment(Environment& environment, const glm::dmat3& rotation);

Environment builtinEnvironment();
// The shadow-test sky: a dim gradient and three small bright suns carrying
// ~80 % of an upward surface's irradiance (assets/suns_environment.h).
Environment sunsEnvironment();
// The same radiance from every direction: the furnace of analytic tests.
Environment constantEnvironment(double radiance);
// A light probe file (EXR, HDR, PFM; lat-long or angular).
Environment environmentFromFile(const std::string& path, const std::string& layout = "auto");

struct Material {
  std::string name;      // as written in the scene ("phong:64"); a MERL file: "merl:" + its stem, never a path
  std::string cacheKey;  // identifies the BRDF for the slice-table cache
  std::shared_ptr<const Brdf> brdf;
  std::string warning;   // non-empty when the file needed a repair (shown to the user)
};

// The albedo of the "lambert" material.
inline constexpr double kLambertAlbedo = 0.8;

// "lambert", "phong:EXP", "blinn-phong:EXP", "ggx:ROUGHNESS", or a MERL
// .binary path (relative to baseDir). Throws std::invalid_argument naming
// the spec.
Material materialFromSpec(const std::string& spec, const std::string& baseDir = ".");

struct SceneObject {
  std::string name;
  std::shared_ptr<const Mesh> mesh;  // object frame
  Material material;
  Pose pose;
  // The scene's ground (addGround): a Lambert plane under the objects that
  // takes their shadows and hides the light below its horizon from them.
  bool ground = false;
  glm::dvec3 groundAlbedo{0.0};
};



struct Camera {
  glm::dvec3 eye{0.0, 0.4, 3.2};
  glm::dvec3 target{0.0};
  glm::dvec3 up{0.0, 1.0, 0.0};
  double fovYDegrees = 35.0;
};

struct Scene {
  Environment environment;
  std::vector<SceneObject> objects;
  Camera camera;
};

// A ground under the objects: a square Lambert plane (+Y up) of half-size
// `extent` × the objects' bounding radius, centred under them, its top at
// the lowest point of their bounds at the scene's poses. Appended as the
// last object, named "ground". Throws std::invalid_argument for an albedo
// outside [0, 1], a non-positive extent, no objects, or a second ground.
// The default albedo is the "lambert" material's, so the ground is named
// "lambert" like any material a client may pick; another is named
// "lambert (albedo A)".
struct GroundOptions {
  double albedo = 0.8;
  double extent = 12.0;
};
void addGround(Scene& scene, const GroundOptions& options = {});

// The built-in default: the procedural sky, a glossy sphere and a torus over a ground.
Scene defaultScene();
// What one scene may hold: a scene file of 10,000 objects would otherwise
// take gigabytes of visibility before its first frame. The refusal names the
// limit and the number asked for; an operator raises them (`serve`,
// `render` and `reference` flags --max-scene-objects, --max-scene-triangles,
// --max-visibility-mb).
struct SceneLimits {
  std::size_t maxObjects = 64;
  std::size_t maxTriangles = 4'000'000;             // all objects together
  std::size_t maxVisibilityBytes = std::size_t{1} << 30;  // per-vertex visibility, all objects
};
// Throws std::invalid_argument naming the limit and the count.
void checkObjectCount(std::size_t objects, const SceneLimits& limits);

// Throws std::runtime_error with the file name and the JSON path of the
// offending key (and the limit, for a scene over `limits`).
Scene loadScene(const std::string& path, const SceneLimits& limits = {});

// Centre a mesh on the origin and scale it to unit bounding radius.
void fitToUnitSphere(Mesh& mesh);

// A mesh's up axis as its file has it: +Y (haarcast's, and most OBJ files)
// or +Z (Lucy, many scans and CAD exports, which otherwise lie on their
// side). Scene files say it per object ("up": "y"|"z"), `render` and
// `reference` with --up.
enum class UpAxis { Y, Z };
// "y" or "z" (either case); throws std::invalid_argument naming the choices.
UpAxis parseUpAxis(const std::string& text);
// Turns a mesh whose up is `up` to stand along +Y: for Z, a rotation of −90°
// about X, (x, y, z) → (x, z, −y), positions and normals alike (a rotation,
// so the winding and the normals' sides are kept). Y changes nothing.
void makeYUp(Mesh& mesh, UpAxis up);

}  // namespace haarcast::render
