// The reference's occlusion modes against analytic answers: a ball above a
// Lambert ground under a constant light (the furnace with one occluder).
//
// Cosine sampling makes each sample of a Lambert surface under a constant
// light L exactly a·L·V(ω) (f/p = (a/π)·L·cos/(cos/π)): with nothing in the
// way the estimate has no variance at all, and with an occluder each sample
// is a Bernoulli variable of mean a·L·(1 − F), F the cosine-weighted fraction
// of the hemisphere the occluder covers. For a ball of radius r whose centre
// is at distance d from the point and height h above its plane, entirely above
// the horizon (h ≥ r), F is the point-to-sphere form factor
//
//   F = (r/d)² · cos β = r²·h/d³
//
// (β the centre's angle from the normal; sin²α for α = asin(r/d) when the
// ball is straight above).
#include <cmath>
#include <iostream>
#include <vector>

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/cpu/reference.h"
#include "haarcast/render/shading.h"

namespace haarcast::render {
namespace {

constexpr double kAlbedo = 0.8;  // materialFromSpec("lambert")
constexpr double kLight = 1.5;

struct Ground {
  Scene scene;
  glm::dvec3 centre;  // the ball's
  double radius;
};

// A Lambert ground (y = 0) and a Lambert ball of radius r centred at height h.
Ground groundAndBall(double groundHalfSize, int subdivisions, double r, const glm::dvec3& centre) {
  Ground g{{}, centre, r};
  g.scene.environment = constantEnvironment(kLight);
  g.scene.objects.push_back({"ground", std::make_shared<Mesh>(assets::makePlane(groundHalfSize, subdivisions)),
                             materialFromSpec("lambert"), {}});
  SceneObject ball{"ball", std::make_shared<Mesh>(assets::makeSphere(64)), materialFromSpec("lambert"), {}};
  ball.pose.translate = centre;
  ball.pose.scale = r;
  g.scene.objects.push_back(ball);
  g.scene.camera.eye = {0.0, 2.6, 3.2};
  g.scene.camera.target = {0.0, 0.0, 0.3};
  g.scene.camera.fovYDegrees = 50.0;
  return g;
}

ReferenceOptions cosineOptions(ReferenceOcclusion occlusion, int size, int samples) {
  ReferenceOptions o;
  o.width = o.height = size;
  o.samplesPerPass = 64;
  o.maxSamples = samples;
  o.tolerance = 0.0;
  o.environmentBackground = false;
  o.sampling = ReferenceSampling::Cosine;
  o.occlusion = occlusion;
  return o;
}

// The ground's pixels: index and world hit point (the reference's own rays).
struct GroundPixel {
  std::size_t index;
  glm::dvec3 point;
};
std::vector<GroundPixel> groundPixels(const Scene& s, int size) {
  std::vector<Instance> instances;
  for (const SceneObject& o : s.objects) instances.push_back({o.mesh.get(), glm::mat4(o.pose.objectToWorld())});
  const RayScene rays(std::move(instances));
  const CameraRays camera(s.camera, size, size);
  std::vector<GroundPixel> out;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      Ray r;
      r.origin = glm::vec3(camera.origin());
      r.direction = glm::vec3(camera.direction(x, y));
      const auto hit = rays.intersect(r);
      if (hit && hit->object == 0) {
        out.push_back({static_cast<std::size_t>(y * size + x), camera.origin() + camera.direction(x, y) * double(hit->t)});
      }
    }
  return out;
}

TEST(ReferenceOcclusion, ABallShadowsTheGroundByItsFormFactor) {
  // The ground posed too (scaled, moved), so that a shadow ray left in an
  // object's frame would miss the ball.
  Ground g = groundAndBall(3.0, 8, 0.5, {0.2, 0.5, 0.1});
  g.scene.objects[0].pose.scale = 2.0;
  g.scene.objects[0].pose.translate = {0.2, -0.5, 0.1};
  g.scene.camera.eye += glm::dvec3(0.2, -0.5, 0.1);
  g.scene.camera.target += glm::dvec3(0.2, -0.5, 0.1);
  const int size = 32, samples = 1024;
  const double aL = kAlbedo * kLight;
  const ReferenceResult none = renderReference(g.scene, cosineOptions(ReferenceOcclusion::None, size, samples));
  const ReferenceResult self = renderReference(g.scene, cosineOptions(ReferenceOcclusion::Self, size, samples));
  const ReferenceResult scene = renderReference(g.scene, cosineOptions(ReferenceOcclusion::Scene, size, samples));
  const std::vector<GroundPixel> ground = groundPixels(g.scene, size);
  ASSERT_GT(ground.size(), 300u);

  // The ball is a UV sphere of 64 segments inscribed in radius r: its
  // silhouette's radius is r·cos(≤ 4°), so F is low by up to 0.5 %.
  const double faceting = 0.005;
  double sumDiff = 0.0, sumVar = 0.0, maxF = 0.0;
  int shaded = 0;
  for (const GroundPixel& p : ground) {
    const std::size_t i = 3 * p.index;
    // Nothing occludes the ground's upper hemisphere but the ball: none and
    // self are the furnace, exactly (cosine sampling has no variance here).
    EXPECT_NEAR(none.image.rgb[i], aL, 1e-5 * aL);
    EXPECT_EQ(self.image.rgb[i], none.image.rgb[i]);
    const glm::dvec3 toCentre = g.centre - p.point;
    const double d = glm::length(toCentre), h = toCentre.y;
    const double F = g.radius * g.radius * h / (d * d * d);
    const double expected = aL * (1.0 - F);
    // Bernoulli per sample (stratification only lowers it); where F·samples
    // is a few, a count is not Gaussian: allow two samples' worth more.
    const double sigma = aL * std::sqrt(F * (1.0 - F) / samples);
    EXPECT_NEAR(scene.image.rgb[i], expected, 5.0 * sigma + faceting * F * aL + 2.0 * aL / samples)
        << "F " << F << " at (" << p.point.x << ", " << p.point.z << ")";
    if (F > 0.02) {
      sumDiff += scene.image.rgb[i] - expected;
      sumVar += sigma * sigma;
      ++shaded;
    }
    maxF = std::max(maxF, F);
  }
  std::cout << ground.size() << " ground pixels, " << shaded << " with F > 2 %, F up to " << maxF
            << "; mean difference from a·L·(1 − F): " << sumDiff / shaded << " (noise "
            << std::sqrt(sumVar) / shaded << ")\n";
  ASSERT_GT(shaded, 40);
  EXPECT_GT(maxF, 0.15);  // the shadow's core is in view
  EXPECT_NEAR(sumDiff / shaded, 0.0, 5.0 * std::sqrt(sumVar) / shaded + faceting * maxF * aL);
}

TEST(ReferenceOcclusion, NoRayReHitsAHugeGroundItLeaves) {
  // A tilted 2000-unit ground seen around a point 50 units from the origin,
  // where a float origin rounds by ~2e-6, and a 1 mm ball far away:
  // shadowOffset × the smallest radius is 1.7e-7, under the rounding (a
  // third of the ground's pixels darken without the floor); the floor of 64
  // ulps of the hit point must keep the rays off the ground. Anywhere in
  // view the ground is then the furnace.
  Ground g = groundAndBall(1000.0, 3, 0.001, {400.0, 0.5, -400.0});
  g.scene.objects[0].pose.rotateDegrees = {13.0, 0.0, 7.0};
  const glm::dmat3 tilt = g.scene.objects[0].pose.rotation();
  g.scene.camera.target = tilt * glm::dvec3(30.0, 0.0, -40.0);
  g.scene.camera.eye = g.scene.camera.target + tilt * glm::dvec3(0.0, 2.0, 2.5);
  g.scene.camera.up = tilt * glm::dvec3(0.0, 1.0, 0.0);
  const int size = 24;
  const ReferenceResult scene = renderReference(g.scene, cosineOptions(ReferenceOcclusion::Scene, size, 256));
  const std::vector<GroundPixel> ground = groundPixels(g.scene, size);
  ASSERT_GT(ground.size(), 200u);
  int dark = 0;
  for (const GroundPixel& p : ground) dark += scene.image.rgb[3 * p.index] < kAlbedo * kLight * (1.0 - 1e-5) ? 1 : 0;
  EXPECT_EQ(dark, 0) << "of " << ground.size() << " ground pixels";
}

TEST(ReferenceOcclusion, ParsedByNameAndCheckedAsAnOption) {
  EXPECT_EQ(parseReferenceOcclusion("scene"), ReferenceOcclusion::Scene);
  EXPECT_EQ(parseReferenceOcclusion("self"), ReferenceOcclusion::Self);
  EXPECT_EQ(parseReferenceOcclusion("none"), ReferenceOcclusion::None);
  EXPECT_FALSE(parseReferenceOcclusion("all").has_value());
  EXPECT_STREQ(referenceOcclusionName(ReferenceOcclusion::Self), "self");
  EXPECT_EQ(ReferenceOptions{}.occlusion, ReferenceOcclusion::Scene);
  ReferenceOptions o;
  o.occlusion = static_cast<ReferenceOcclusion>(7);
  try {
    checkReferenceOptions(o);
    ADD_FAILURE() << "an unknown occlusion was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("scene, self, none"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace haarcast::render
