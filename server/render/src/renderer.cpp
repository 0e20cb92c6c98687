// What both backends share: one definition of every number.
#include "haarcast/render/renderer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "haarcast/core/lobe.h"
#include "haarcast/core/shared_cells.h"
#include "haarcast/core/splitsum.h"
#include "haarcast/io/slice_cache.h"
#include "haarcast/render/build_plan.h"
#include "haarcast/render/object_levels.h"
#include "haarcast/render/shading.h"
#include "haarcast/render/visibility_cache.h"

namespace haarcast::render {

// ---------------------------------------------------------------- shared steps

BrdfSliceTable objectSliceTable(const SceneObject& object, const RenderOptions& options, const RenderProgress& progress) {
  return objectSliceTable(object, options, options.level, progress);
}

BrdfSliceTable objectSliceTable(const SceneObject& object, const RenderOptions& options, int level,
                                const RenderProgress& progress, std::string_view stage) {
  SliceTableOptions table;
  table.level = level;
  table.thetaSamples = options.thetaSamples;
  table.supersampling = options.sliceSupersampling;
  const std::string name = std::string(stage) + " " + object.name;
  auto tableProgress = [&](int done, int total) {
    if (progress) progress(name, static_cast<std::size_t>(done), static_cast<std::size_t>(total));
  };
  return options.cacheDir.empty() ? BrdfSliceTable::build(*object.material.brdf, table, tableProgress)
                                  : io::loadOrBuildSliceTable(*object.material.brdf, table, options.cacheDir,
                                                              object.material.cacheKey, tableProgress);
}

PreparedScene prepareScene(const Scene& scene, const RenderOptions& options, const RenderProgress& progress) {
  checkRenderOptions(options);
  if (scene.objects.empty()) throw std::invalid_argument("render: the scene has no objects");
  // The scene's size against the operator's limits, before anything is
  // computed: triangles, and what the visibility will hold (fused: bits per
  // vertex; the Haar methods: `keep` entries of 8 bytes per vertex).
  checkObjectCount(scene.objects.size(), options.sceneLimits);
  // splitsum keeps none: its visibility is one ray per pixel.
  const bool splitsum = options.method == RotationMethod::Splitsum;
  const bool fused = options.method == RotationMethod::Fused;
  std::size_t triangles = 0;
  for (const SceneObject& object : scene.objects) triangles += object.mesh->triangles.size();
  if (triangles > options.sceneLimits.maxTriangles) {
    throw std::invalid_argument("render: the scene has " + std::to_string(triangles) + " triangles, over the limit of " +
                                std::to_string(options.sceneLimits.maxTriangles) + " (--max-scene-triangles)");
  }
  // Each object's level (its lobes measured, for `fused`): the visibility
  // is counted at each object's own.
  std::vector<ObjectPlan> levels = planObjects(scene, options);
  auto perVertex = [&](int level) -> std::size_t {
    return splitsum ? 0
           : fused  ? 4 * visibilityWordsPerPoint(level)
                    : 8 * std::min<std::size_t>(options.visibility.keep, std::size_t{1} << (2 * level));
  };
  std::size_t visibilityBytes = 0;
  int finest = 0;
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    visibilityBytes += scene.objects[k].mesh->positions.size() * perVertex(levels[k].level);
    finest = std::max(finest, levels[k].level);
  }
  if (visibilityBytes > options.sceneLimits.maxVisibilityBytes) {
    throw std::invalid_argument("render: the scene's visibility would take " + std::to_string(visibilityBytes >> 20) +
                                " MB at level " + std::to_string(finest) + (options.automaticLevel ? " at most" : "") +
                                ", over the limit of " + std::to_string(options.sceneLimits.maxVisibilityBytes >> 20) +
                                " MB (--max-visibility-mb)");
  }
  // Refinement adds vertices (visibility_refine.h: up to max(growth × V,
  // floor) an object); where that could pass the limit, the scene is drawn
  // unrefined rather than over the operator's memory cap.
  RefineOptions refine = options.refine;
  if (fused && refine.rounds > 0) {
    std::size_t bound = 0;
    for (std::size_t k = 0; k < scene.objects.size(); ++k) {
      const SceneObject& object = scene.objects[k];
      const std::size_t v = object.mesh->positions.size();
      bound += perVertex(levels[k].level) *
               (object.ground ? v : refineVertexBudget(v, refine));
    }
    if (bound > options.sceneLimits.maxVisibilityBytes) refine.rounds = 0;
  }
  PreparedScene prepared;
  prepared.scene = scene;
  prepared.objects.resize(scene.objects.size());
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    const SceneObject& object = scene.objects[k];
    PreparedObject& p = prepared.objects[k];
    p.name = object.name;
    p.pose = object.pose;
    p.level = levels[k].level;
    p.pointLevel = p.level;
    object.mesh->validate();
    p.mesh = withNormals(object.mesh);  // a mesh built in code may come without them
    // splitsum's only precompute is its lobes (below): no slice table.
    if (!splitsum) p.table = objectSliceTable(object, options, p.level, progress);
    p.ground = object.ground;
    p.groundAlbedo = object.groundAlbedo;
    p.sumTolerance = levels[k].sumTolerance;
    p.sharpestLobe = levels[k].sharpestLobe;
    p.plan = describePlan(levels[k], p.ground, options.method);
    p.sphereCentre = p.mesh->bounds().centre();
    for (const glm::vec3& v : p.mesh->positions) p.sphereRadius = std::max(p.sphereRadius, glm::length(glm::dvec3(v) - p.sphereCentre));
    if (p.ground) {
      if (prepared.ground) throw std::invalid_argument("render: the scene has two grounds");
      prepared.ground = k;
    }
    VisibilityOptions vis = options.visibility;
    vis.level = p.level;
    p.shadowShift = static_cast<float>(vis.offset * p.mesh->bounds().radius());
    auto visibilityProgress = [&](std::size_t done, std::size_t total) {
      if (progress) progress("visibility " + object.name, done, total);
    };
    if (splitsum) {
      // The lobe of every θₒ sample, the ground's too: every pixel reads the
      // prefiltered light along its mirror direction (core/splitsum.h).
      p.lobes = measureLobes(*object.material.brdf, lobeThetaOut(options.thetaSamples));
      p.lobePath = true;
    } else if (fused) {
      if (p.ground || refine.rounds == 0) {
        p.visibilityBits = loadOrComputeVisibilityBits(*p.mesh, vis, options.cacheDir, visibilityProgress);
      } else {
        RefinedVisibility r = loadOrComputeRefinedVisibility(*p.mesh, vis, refine, options.cacheDir, visibilityProgress);
        p.mesh = std::make_shared<const Mesh>(std::move(r.mesh));
        p.visibilityBits = std::move(r.bits);
      }
      if (shared::sumsByCells(static_cast<shared::uint>(p.level), p.sumTolerance))
        p.cellVisibility = CellVisibility::fromBits(p.visibilityBits);
    } else {
      p.visibility = loadOrComputeVertexVisibility(*p.mesh, vis, options.cacheDir, visibilityProgress);
    }
  }
  prepared.light = scene.environment.maps(options.level);
  prepared.background = scene.environment.maps(kBackgroundLevel);
  if (splitsum) prepared.lobeLight = PrefilteredLight::build(prepared.background);
  if (fused) {
    // Lights found on the backdrop's fine map (light_split.h: their
    // directions to a tenth of a degree), the rest at each level in use and
    // at kSkyRaysLevel: the solid-angle mean of the fine map's rest
    // (SphereMap::downsampled).
    LightSplit split = splitLight(prepared.background, options.pointLights);
    prepared.pointLights = std::move(split.lights);
    prepared.restLight.assign(static_cast<std::size_t>(kBackgroundLevel) + 1, {});
    std::vector<int> restLevels{kSkyRaysLevel};
    for (const int level : levelsInUse(prepared.objectLevels())) restLevels.insert(restLevels.end(), {level, lightTurnLevel(level)});
    for (const int at : restLevels) {
      std::array<SphereMap, 3>& rest = prepared.restLight[static_cast<std::size_t>(at)];
      if (rest[0].level() == at && rest[0].pixelCount() > 1) continue;
      for (std::size_t c = 0; c < 3; ++c) rest[c] = split.rest[c].downsampled(at);
    }
    for (std::size_t k = 0; k < prepared.objects.size(); ++k) {
      PreparedObject& p = prepared.objects[k];
      if (p.ground) continue;  // shaded in closed form
      std::vector<double> thetaOut;
      for (int t = 0; t < p.table.thetaSamples(); ++t) thetaOut.push_back(p.table.thetaOut(t));
      // Point lights read the slices at one direction each: a finer table
      // where the lobe is narrow costs memory and build time only.
      if (!prepared.pointLights.empty()) {
        p.pointLevel = pointLightLevel(levels[k].lobes, p.level);
        if (p.pointLevel != p.level) {
          p.pointTable = objectSliceTable(scene.objects[k], options, p.pointLevel, progress, kPointSlicesStage);
        }
      }
      LobeCore core = chooseLobeCore(*scene.objects[k].material.brdf, thetaOut, p.level, std::move(levels[k].lobes));
      p.lobes = std::move(core.lobes);
      p.lobeCore = core.angle;
      p.lobePath = p.lobeCore > 0.0f;
      // The prefiltered light (5.6 MB at level 9) only where a pixel can read it.
      if (p.lobePath && prepared.lobeLight.empty()) prepared.lobeLight = PrefilteredLight::build(prepared.background);
    }
    const std::array<SphereMap, 3>& rest = prepared.restLightAt(kSkyRaysLevel);
    prepared.restLuminance = SphereMap(rest[0].level());
    for (int r = 0; r < rest[0].size(); ++r)
      for (int c = 0; c < rest[0].size(); ++c)
        prepared.restLuminance.at(r, c) = static_cast<float>(luminance709(rest[0].at(r, c), rest[1].at(r, c), rest[2].at(r, c)));
  }
  return prepared;
}

const std::array<SphereMap, 3>& PreparedScene::restLightAt(int level) const {
  if (level < 0 || static_cast<std::size_t>(level) >= restLight.size() || restLight[static_cast<std::size_t>(level)][0].level() != level ||
      restLight[static_cast<std::size_t>(level)][0].pixelCount() <= 1) {
    throw std::out_of_range("render: no rest light at level " + std::to_string(level) + " (no object uses it)");
  }
  return restLight[static_cast<std::size_t>(level)];
}

std::vector<std::string> PreparedScene::objectPlans() const {
  std::vector<std::string> out;
  for (const PreparedObject& p : objects) out.push_back(p.plan);
  return out;
}

std::vector<int> PreparedScene::pointLightLevels() const {
  std::vector<int> out;
  for (const PreparedObject& p : objects) out.push_back(p.pointLevel);
  return out;
}

std::vector<int> PreparedScene::objectLevels() const {
  std::vector<int> out;
  for (const PreparedObject& p : objects) out.push_back(p.level);
  return out;
}

std::array<SparseHaar, 3> lightInObjectFrame(const std::array<SphereMap, 3>& worldLight, const glm::dmat3& objectRotation,
                                             const glm::dmat3& lightRotation, std::size_t k) {
  // L_obj(ω) = L(Mω) with M = lightRotationᵀ·objectRotation; rotating a map
  // by E gives g(ω) = f(Eᵀω), so E = Mᵀ.
  const EulerYXY toObject = eulerFromMatrix(glm::transpose(glm::transpose(lightRotation) * objectRotation));
  std::array<SparseHaar, 3> light;
  for (std::size_t c = 0; c < 3; ++c) {
    const SphereMap local = rotateSpatialMap(worldLight[c], toObject);
    light[c] = keepLargest(forwardHaar(local.weightedBySolidAngle()), k);
  }
  return light;
}

RotationInput rotationInput(const glm::dvec3& normal, const glm::dvec3& towardEye) {
  double thetaOut = 0.0;
  RotationInput in;
  in.euler = eulerFromMatrix(shadingFrame(normal, towardEye, thetaOut));
  in.thetaOut = thetaOut;
  return in;
}

RotationInput rotationInput(const glm::dvec3& normal, const glm::dvec3& towardEye, const BrdfSliceTable& table) {
  RotationInput in = rotationInput(normal, towardEye);
  in.slice = table.nearestSlice(in.thetaOut);
  return in;
}

glm::vec3 backdropRadiance(const std::array<SphereMap, 3>& background, const glm::mat3& toEnvironment, const glm::vec3& direction) {
  const shared::LatLongTaps t = latLongTapsToward(background[0].level(), toEnvironment * direction);
  return {valueAt(background[0], t), valueAt(background[1], t), valueAt(background[2], t)};
}

void checkFrameRequest(const FrameRequest& r, std::size_t objectCount) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("frame request: " + what); };
  if (r.width < 1 || r.height < 1 || r.width > kMaxFrameSide || r.height > kMaxFrameSide) {
    bad("resolution " + std::to_string(r.width) + "×" + std::to_string(r.height) + " is outside 1.." +
        std::to_string(kMaxFrameSide));
  }
  if (!r.poses.empty() && r.poses.size() != objectCount) {
    bad(std::to_string(r.poses.size()) + " poses for " + std::to_string(objectCount) + " objects");
  }
  if (!(r.camera.fovYDegrees >= kMinFovDegrees && r.camera.fovYDegrees <= kMaxFovDegrees)) {
    bad("camera fov " + std::to_string(r.camera.fovYDegrees) + "° is outside " + std::to_string(kMinFovDegrees) +
        ".." + std::to_string(kMaxFovDegrees) + "°");
  }
  const glm::dvec3 view = r.camera.target - r.camera.eye;
  const double distance = glm::length(view);
  if (!(distance >= kMinEyeDistance && distance <= kMaxEyeDistance)) {
    bad("camera eye-to-target distance " + std::to_string(distance) + " is outside " + std::to_string(kMinEyeDistance) +
        ".." + std::to_string(kMaxEyeDistance));
  }
  if (!(glm::length(glm::cross(view, r.camera.up)) > 1e-9 * distance)) {
    bad("camera up must be finite, non-zero and not along the view direction");
  }
  for (const Pose& p : r.poses) {
    if (!std::isfinite(p.rotateDegrees.x + p.rotateDegrees.y + p.rotateDegrees.z + p.translate.x + p.translate.y +
                       p.translate.z) ||
        !(p.scale > 0.0 && std::isfinite(p.scale))) {
      bad("a pose is not finite (or its scale is not positive)");
    }
  }
  const ExposureControl& e = r.exposure;
  if (!e.automatic && !(std::abs(e.stops) <= kMaxExposureStops)) {
    bad("exposure " + std::to_string(e.stops) + " stops is outside ±" + std::to_string(static_cast<int>(kMaxExposureStops)));
  }
  if (e.previousStops && !(std::abs(*e.previousStops) <= kMaxExposureStops)) bad("previous exposure is not finite");
  if (!(e.adaptation >= 0.0 && e.adaptation <= 1.0)) bad("exposure adaptation must be in 0..1");
}

namespace {

// fused's point lights for one object: their directions in its frame, and
// for the ground its closed form's share of each, ρ·cos θ·power where seen.
void resolveFusedPointLights(const PreparedScene& prepared, const PreparedObject& object,
                             const std::vector<glm::vec3>& worldDirections, ResolvedObject& o) {
  o.pointLights.resize(worldDirections.size());
  for (std::size_t k = 0; k < worldDirections.size(); ++k) {
    const glm::dvec3 d = glm::transpose(o.rotation) * glm::dvec3(worldDirections[k]);
    o.pointLights[k].direction = glm::vec3(d);
    for (std::size_t c = 0; c < 3; ++c) o.pointLights[k].power[c] = static_cast<float>(prepared.pointLights[k].power[c]);
  }
  if (!object.ground) return;
  // The ground is a Lambert plane with +Y up in its own frame and nothing of
  // its own above it: ρ·cos θ = albedo/π·max(y, 0) at every point, so each
  // point light adds a constant where seen (and the map part is one sum per
  // frame, resolveFusedLight's groundFlat).
  const glm::dvec3 rho = object.groundAlbedo / kPi;
  for (FusedPointLight& l : o.pointLights) {
    const double cosine = std::max(0.0, static_cast<double>(l.direction.y));
    for (std::size_t c = 0; c < 3; ++c) l.power[c] = static_cast<float>(rho[static_cast<int>(c)] * cosine * l.power[c]);
  }
}

// fused's light for one object (ResolvedObject): the rest map in the
// object's frame, weighted by ΔΩ, zero where the ground hides it; the point
// lights in the object's frame; and for the ground itself its closed form.
// shaders/light.comp computes the same map light on the device.
void resolveFusedLight(const PreparedScene& prepared, const PreparedObject& object, const glm::dmat3& lightRotation,
                       const std::optional<glm::dvec3>& groundNormal, const std::vector<glm::vec3>& worldDirections,
                       ResolvedObject& o) {
  // L_obj(ω) = L(Mω), M = lightRotationᵀ·objectRotation (lightInObjectFrame).
  const EulerYXY toObject = eulerFromMatrix(glm::transpose(glm::transpose(lightRotation) * o.rotation));
  std::array<SphereMap, 3> weighted =
      rotateSpatialMapsDown(prepared.restLightAt(lightTurnLevel(object.level)), toObject, object.level);
  for (SphereMap& map : weighted) map = map.weightedBySolidAngle();
  const int level = weighted[0].level();
  const int m = mapSize(level);
  if (groundNormal && !object.ground) {
    // What the ground hides: every direction below its plane, as seen from
    // above it (the plane is wide: DESIGN.md's direct light has no bounce).
    const glm::dvec3 down = glm::transpose(o.rotation) * *groundNormal;  // the ground's normal in the object's frame
    for (int r = 0; r < m; ++r)
      for (int col = 0; col < m; ++col)
        if (glm::dot(sphericalToDirection(rowTheta(level, r), colPhi(level, col)), down) < 0.0)
          for (std::size_t c = 0; c < 3; ++c) weighted[c].at(r, col) = 0.0f;
  }
  o.fusedLight = FusedLight::fromWeightedMaps(weighted, object.sumTolerance);
  resolveFusedPointLights(prepared, object, worldDirections, o);
  if (!object.ground) return;
  // The ground's map part: ρ·Σ_{y>0} (L·ΔΩ)·y, one sum per frame.
  const glm::dvec3 rho = object.groundAlbedo / kPi;
  glm::dvec3 flat(0.0);
  for (int r = 0; r < m; ++r) {
    const double y = std::cos(rowTheta(level, r));
    if (y <= 0.0) continue;
    for (int col = 0; col < m; ++col)
      for (int c = 0; c < 3; ++c) flat[c] += weighted[static_cast<std::size_t>(c)].at(r, col) * y;
  }
  for (int c = 0; c < 3; ++c) o.groundFlat[static_cast<std::size_t>(c)] = static_cast<float>(rho[c] * flat[c]);
}

}  // namespace

struct FusedLightCache::Entry {
  Key key;
  FusedLight fusedLight;
  std::vector<FusedPointLight> pointLights;
  std::array<float, 3> groundFlat{};
};

bool FusedLightCache::find(std::size_t index, const Key& key, ResolvedObject& o) const {
  std::shared_ptr<const Entry> entry;
  {
    const std::lock_guard lock(mutex_);
    if (index < entries_.size()) entry = entries_[index];
  }
  if (!entry || !(entry->key == key)) return false;
  o.fusedLight = entry->fusedLight;
  o.pointLights = entry->pointLights;
  o.groundFlat = entry->groundFlat;
  hits_.fetch_add(1);
  return true;
}

void FusedLightCache::store(std::size_t index, const Key& key, const ResolvedObject& o) {
  auto entry = std::make_shared<const Entry>(Entry{key, o.fusedLight, o.pointLights, o.groundFlat});
  const std::lock_guard lock(mutex_);
  if (entries_.size() <= index) entries_.resize(index + 1);
  entries_[index] = std::move(entry);
}

glm::dmat3 lightRotationOf(const PreparedScene& prepared, const FrameRequest& request) {
  return request.lightRotation * prepared.scene.environment.rotation;
}

ResolvedFrame resolveFrame(const PreparedScene& prepared, const RenderOptions& options, const FrameRequest& request,
                           FusedMapLight mapLight) {
  checkFrameRequest(request, prepared.objects.size());
  ResolvedFrame out;
  const glm::dmat3 light = lightRotationOf(prepared, request);
  out.lightRotation = light;
  out.lightCoefficients = request.lightCoefficients ? request.lightCoefficients : options.lightCoefficients;
  out.objects.resize(prepared.objects.size());
  const bool fused = options.method == RotationMethod::Fused;
  // A light at d in the environment's frame is seen at lightRotation·d (L'(ω) = L(Rᵀω)).
  if (fused) {
    for (const DirectionalLight& l : prepared.pointLights)
      out.pointLightDirections.push_back(glm::vec3(glm::normalize(light * l.direction)));
  }
  for (std::size_t i = 0; i < out.objects.size(); ++i) {
    const Pose& pose = request.poses.empty() ? prepared.objects[i].pose : request.poses[i];
    ResolvedObject& o = out.objects[i];
    o.rotation = pose.rotation();
    o.objectToWorld = pose.objectToWorld();
    o.scale = pose.scale;
    o.toLight = glm::mat3(glm::transpose(light) * o.rotation);
  }
  out.camera = cameraBasis(request.camera, request.width, request.height);
  {
    // Near plane: a fraction of the nearest posed object's bounding-sphere distance.
    double nearest = std::numeric_limits<double>::infinity(), farthest = 0.0;
    for (std::size_t i = 0; i < out.objects.size(); ++i) {
      const Bounds b = prepared.objects[i].mesh->bounds();
      const glm::dvec3 centre = glm::dvec3(out.objects[i].objectToWorld * glm::dvec4(b.centre(), 1.0));
      const double radius = b.radius() * out.objects[i].scale;
      const double d = glm::length(centre - request.camera.eye);
      nearest = std::min(nearest, d - radius);
      farthest = std::max(farthest, d + radius);
    }
    const double nearPlane = nearest > 0.0 ? std::max(0.5 * nearest, 1e-6 * farthest) : 1e-6 * std::max(farthest, 1.0);
    out.viewProjection = viewProjection(request.camera, out.camera, request.width, request.height, nearPlane);
  }
  std::optional<glm::dvec3> groundNormal;
  if (prepared.ground) groundNormal = out.objects[*prepared.ground].rotation * glm::dvec3(0.0, 1.0, 0.0);
  const std::size_t standing = prepared.standingObjects();
  if (fused && (prepared.ground || standing >= 2)) {
    // The sky the objects hide from the ground and from each other
    // (point_lights.h): their bounding spheres as posed, the map light, its
    // luminance and its total over the ground's hemisphere.
    SkyOccluders& sky = out.skyOccluders;
    sky.ground = prepared.ground.has_value();
    if (groundNormal) sky.normal = glm::vec3(*groundNormal);
    sky.objectSky = options.objectSky && standing >= 2;
    sky.toEnvironment = glm::mat3(glm::transpose(light));
    for (std::size_t i = 0; i < out.objects.size(); ++i) {
      if (prepared.objects[i].ground) continue;
      const PreparedObject& p = prepared.objects[i];
      const glm::dvec3 centre = glm::dvec3(out.objects[i].objectToWorld * glm::dvec4(p.sphereCentre, 1.0));
      sky.occluders.emplace_back(glm::vec3(centre), static_cast<float>(p.sphereRadius * out.objects[i].scale));
      sky.objects.push_back(static_cast<std::uint32_t>(i));
    }
    sky.luminance = &prepared.restLuminance;
    const int level = prepared.restLuminance.level();
    sky.colour = &prepared.restLightAt(level);
    for (int r = 0; groundNormal && r < prepared.restLuminance.size(); ++r) {
      for (int c = 0; c < prepared.restLuminance.size(); ++c) {
        const double cosine = glm::dot(light * sphericalToDirection(rowTheta(level, r), colPhi(level, c)), *groundNormal);
        if (cosine > 0.0) sky.total += prepared.restLuminance.at(r, c) * cosine * pixelSolidAngle(level, r);
      }
    }
  }
  for (std::size_t i = 0; i < out.objects.size(); ++i) {
    ResolvedObject& o = out.objects[i];
    if (fused && mapLight == FusedMapLight::Device) {
      resolveFusedPointLights(prepared, prepared.objects[i], out.pointLightDirections, o);
      const auto n = static_cast<std::size_t>(mapSize(prepared.objects[i].level));
      out.lightBytes += 3 * n * n * sizeof(float);  // what the device's light holds: resolveFusedLight's planes
      continue;
    }
    if (fused) {
      // Everything resolveFusedLight reads that a request changes.
      const FusedLightCache::Key key{light, o.rotation, groundNormal};
      if (!prepared.fusedLightCache->find(i, key, o)) {
        resolveFusedLight(prepared, prepared.objects[i], light, groundNormal, out.pointLightDirections, o);
        prepared.fusedLightCache->store(i, key, o);
      }
      out.lightBytes += o.fusedLight.planes.size() * sizeof(float);
      continue;
    }
    if (options.method == RotationMethod::Splitsum) continue;  // it turns the lookup (toLight), not the light
    o.light = lightInObjectFrame(prepared.light, o.rotation, light, out.lightCoefficients);
    for (const SparseHaar& l : o.light) out.lightBytes += l.size() * (sizeof(std::uint32_t) + sizeof(float));
  }
  return out;
}

}  // namespace haarcast::render
