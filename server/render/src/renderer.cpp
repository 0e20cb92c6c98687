// What both backends share: one definition of every number.
#include "haarcast/render/renderer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

#include "haarcast/io/slice_cache.h"
#include "haarcast/render/shading.h"
#include "haarcast/render/visibility_cache.h"

namespace haarcast::render {

// ---------------------------------------------------------------- shared steps

void checkRenderOptions(const RenderOptions& o) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("render options: " + what); };
  if (o.width < 1 || o.height < 1 || o.width > kMaxFrameSide || o.height > kMaxFrameSide) {
    bad("resolution " + std::to_string(o.width) + "×" + std::to_string(o.height) + " is outside 1.." +
        std::to_string(kMaxFrameSide));
  }
  if (o.level < kMinRenderLevel || o.level > kMaxRenderLevel) {
    bad("level " + std::to_string(o.level) + " is outside " + std::to_string(kMinRenderLevel) + ".." +
        std::to_string(kMaxRenderLevel));
  }
  if (o.lightCoefficients == 0) bad("light coefficients must be at least 1");
  if (o.thetaSamples < 1 || o.thetaSamples > 256) bad("theta samples must be in 1..256");
}

BrdfSliceTable objectSliceTable(const SceneObject& object, const RenderOptions& options, const RenderProgress& progress) {
  SliceTableOptions table;
  table.level = options.level;
  table.thetaSamples = options.thetaSamples;
  table.supersampling = options.sliceSupersampling;
  auto tableProgress = [&](int done, int total) {
    if (progress) progress("slices " + object.name, static_cast<std::size_t>(done), static_cast<std::size_t>(total));
  };
  return options.cacheDir.empty() ? BrdfSliceTable::build(*object.material.brdf, table, tableProgress)
                                  : io::loadOrBuildSliceTable(*object.material.brdf, table, options.cacheDir,
                                                              object.material.cacheKey, tableProgress);
}

PreparedScene prepareScene(const Scene& scene, const RenderOptions& options, const RenderProgress& progress) {
  checkRenderOptions(options);
  if (scene.objects.empty()) throw std::invalid_argument("render: the scene has no objects");
  PreparedScene prepared;
  prepared.scene = scene;
  prepared.objects.resize(scene.objects.size());
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    const SceneObject& object = scene.objects[k];
    PreparedObject& p = prepared.objects[k];
    p.name = object.name;
    p.pose = object.pose;
    object.mesh->validate();
    p.mesh = withNormals(object.mesh);  // a mesh built in code may come without them
    p.table = objectSliceTable(object, options, progress);
    VisibilityOptions vis = options.visibility;
    vis.level = options.level;
    p.visibility = loadOrComputeVertexVisibility(*p.mesh, vis, options.cacheDir, [&](std::size_t done, std::size_t total) {
      if (progress) progress("visibility " + object.name, done, total);
    });
  }
  prepared.light = scene.environment.maps(options.level);
  prepared.background = scene.environment.maps(kBackgroundLevel);
  return prepared;
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

RotationInput rotationInput(const glm::dvec3& normal, const glm::dvec3& towardEye, const BrdfSliceTable& table) {
  double thetaOut = 0.0;
  RotationInput in;
  in.euler = eulerFromMatrix(shadingFrame(normal, towardEye, thetaOut));
  in.slice = table.nearestSlice(thetaOut);
  in.thetaOut = thetaOut;
  return in;
}

glm::dvec3 backgroundRadiance(const std::array<SphereMap, 3>& background, const glm::dmat3& lightRotation,
                              const glm::dvec3& direction) {
  // L'(ω) = L(Rᵀω).
  const Spherical s = directionToSpherical(glm::transpose(lightRotation) * direction);
  const int level = background[0].level();
  const BilinearTaps taps = bilinearTaps(level, s.theta, s.phi);
  glm::dvec3 out(0.0);
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      const double w = taps.weight(a, b);
      for (int c = 0; c < 3; ++c) {
        out[c] += w * background[static_cast<std::size_t>(c)].at(taps.row[static_cast<std::size_t>(a)],
                                                                  taps.col[static_cast<std::size_t>(b)]);
      }
    }
  }
  return out;
}

double frameLogAverage(const io::RgbImage& image, const std::vector<std::uint8_t>& objectMask) {
  const double objects = logAverageLuminance(image, objectMask);
  return objects > 0.0 ? objects : logAverageLuminance(image);
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

ResolvedFrame resolveFrame(const PreparedScene& prepared, const RenderOptions& options, const FrameRequest& request) {
  checkFrameRequest(request, prepared.objects.size());
  ResolvedFrame out;
  out.lightCoefficients = request.lightCoefficients ? request.lightCoefficients : options.lightCoefficients;
  out.objects.resize(prepared.objects.size());
  for (std::size_t i = 0; i < out.objects.size(); ++i) {
    const Pose& pose = request.poses.empty() ? prepared.objects[i].pose : request.poses[i];
    ResolvedObject& o = out.objects[i];
    o.rotation = pose.rotation();
    o.objectToWorld = pose.objectToWorld();
    o.scale = pose.scale;
    o.light = lightInObjectFrame(prepared.light, o.rotation, request.lightRotation, out.lightCoefficients);
    for (const SparseHaar& l : o.light) out.lightBytes += l.size() * (sizeof(std::uint32_t) + sizeof(float));
    if (options.method == RotationMethod::Fused) o.fusedLight = FusedLight::synthesize(o.light);
  }
  return out;
}

}  // namespace haarcast::render
