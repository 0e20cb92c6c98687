// The sky objects hide from each other (render/point_lights.h
// objectSkyHidden, fused's `hidden` light) against the closed form of two
// balls under a constant sky: a sphere of radius r whose centre lies at
// distance d along a point's normal hides π·(r/d)² of the point's
// Σ L·cos·ΔΩ (its projected solid angle, π·sin²α).
#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/render/point_lights.h"
#include "haarcast/render/renderer.h"

namespace haarcast::render {
namespace {

constexpr double kSky = 0.5;     // radiance of the sky, everywhere
constexpr double kAlbedo = 0.8;  // the balls' Lambert albedo
constexpr double kRadius = 0.5;

Environment constantSky() {
  Environment e;
  e.name = "constant sky";
  e.radiance = [](const glm::dvec3&) { return glm::dvec3(kSky); };
  e.maps = [](int level) {
    const SphereMap m = supersampledMap(level, 1, [](const glm::dvec3&) { return kSky; });
    return std::array<SphereMap, 3>{m, m, m};
  };
  return e;
}

// The two balls: A at the origin, B at `b`, both of radius kRadius.
glm::mat4 placed(const glm::vec3& at) {
  return glm::mat4(glm::vec4(kRadius, 0, 0, 0), glm::vec4(0, kRadius, 0, 0), glm::vec4(0, 0, kRadius, 0), glm::vec4(at, 1));
}

struct TwoBalls {
  Mesh sphere = assets::makeSphere(64);
  SphereMap luminance = supersampledMap(6, 1, [](const glm::dvec3&) { return kSky; });
  std::array<SphereMap, 3> colour{luminance, luminance, luminance};
  SkyOccluders sky;

  explicit TwoBalls(const glm::vec3& b) {
    sky.occluders = {glm::vec4(0, 0, 0, kRadius), glm::vec4(b, kRadius)};
    sky.objects = {0, 1};
    sky.luminance = &luminance;
    sky.colour = &colour;
    sky.objectSky = true;
  }
};

TEST(ObjectSky, ABallHidesItsProjectedSolidAngleFromItsNeighbour) {
  for (const float d : {0.75f, 1.0f, 2.0f}) {
    // The point of A that faces B, at distance d from B's centre.
    const glm::vec3 b(kRadius + d, 0.0f, 0.0f);
    TwoBalls scene(b);
    const RayScene world({Instance{&scene.sphere, placed(glm::vec3(0.0f))}, Instance{&scene.sphere, placed(b)}});
    const ShadingPoint p{glm::vec3(kRadius, 0.0f, 0.0f), glm::vec3(1.0f, 0.0f, 0.0f), 1e-4f};
    const SkyHidden h = objectSkyHidden(world, p, 0, scene.sky);
    const double expected = kSky * kPi * (kRadius / d) * (kRadius / d);
    const double got = h.power.x;  // Σ L·cos·ΔΩ hidden (shared_rays.h HiddenLight)
    EXPECT_NEAR(got, expected, 0.03 * expected) << "d = " << d;
    EXPECT_GT(h.direction.x, 0.99f) << "toward B";
  }
}

TEST(ObjectSky, WhatAnObjectHidesFromItselfIsNotTakenTwice) {
  // A point under a lid, B straight above both. Rays toward B that the
  // lid blocks are the lid's: when the point is on the lid's own object
  // they are its visibility already and not taken again; when the lid is
  // another object they are hidden sky.
  const glm::vec3 b(0.0f, 2.0f, 0.0f);
  TwoBalls scene(b);
  const Mesh lid = assets::makeBox(2.0, 0.2, 2.0);
  const Mesh dot = assets::makeSphere(8);
  const RayScene world({Instance{&lid, glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.5f, 0.0f))},
                        Instance{&scene.sphere, placed(b)},
                        Instance{&dot, glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, 9.0f))}});
  const ShadingPoint under{glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f), 1e-4f};
  SkyOccluders& sky = scene.sky;
  sky.occluders[0] = glm::vec4(0.0f, 0.5f, 0.0f, 3.0f);
  EXPECT_EQ(objectSkyHidden(world, under, 0, sky).power.x, 0.0f) << "the point's own object hides B's cone";
  sky.objects = {2, 1};
  EXPECT_GT(objectSkyHidden(world, under, 2, sky).power.x, 0.0f) << "another object hides B's cone";
}

TEST(ObjectSky, PackedDirectionsComeBackWithinATenThousandthOfARadian) {
  for (int i = 0; i < 500; ++i) {
    const double z = 1.0 - 2.0 * (i + 0.5) / 500.0, phi = i * 2.399963;
    const glm::vec3 d(std::sqrt(1.0 - z * z) * std::cos(phi), std::sqrt(1.0 - z * z) * std::sin(phi), z);
    const glm::vec3 back = shared::unpackDirection(shared::packDirection(d));
    // The angle from the cross product: acos of a float dot near 1 is coarser than the packing.
    EXPECT_LT(std::asin(std::min(1.0, glm::length(glm::cross(glm::dvec3(d), glm::dvec3(back))))), 1e-4) << i;
  }
}

// Frames: A's side that faces B is darker by what B hides, and lit again
// when B moves away in the next frame's poses.
TEST(ObjectSky, NeighboursDarkenEachOthersSidesInTheFrame) {
  Scene s;
  s.environment = constantSky();
  const auto ball = [](const char* name, const glm::dvec3& at) {
    SceneObject o{name, std::make_shared<Mesh>(assets::makeSphere(64)), materialFromSpec("lambert"), {}};
    o.material.brdf = makeLambert(glm::dvec3(kAlbedo));
    o.material.cacheKey = "lambert-0.8";
    o.pose.translate = at;
    o.pose.scale = kRadius;
    return o;
  };
  // B along (1, 0, −1)/√2 from A, 1.25 apart: A's point p facing it is
  // 0.75 from B's centre. The camera looks at p from above its normal.
  const glm::dvec3 axis = glm::normalize(glm::dvec3(1.0, 0.0, -1.0));
  const double d = 0.75;
  s.objects = {ball("a", {0.0, 0.0, 0.0}), ball("b", axis * (kRadius + d))};
  const glm::dvec3 p = axis * kRadius;
  s.camera.target = p;
  s.camera.eye = p + 3.0 * glm::normalize(axis + glm::dvec3(0.0, 1.5, 0.0));
  RenderOptions o;
  o.width = o.height = 9;
  o.level = 5;
  o.thetaSamples = 4;
  o.visibility.supersampling = 1;
  o.environmentBackground = false;
  const auto renderer = makeCpuRenderer(s, o);
  FrameRequest request;
  request.width = o.width;
  request.height = o.height;
  request.camera = s.camera;
  const auto centre = [](const Frame& f) { return f.image.at(f.height / 2, f.width / 2, 0); };
  const float beside = centre(renderer->render(request));
  request.poses = {s.objects[0].pose, Pose{{0.0, 0.0, 0.0}, {0.0, 0.0, 40.0}, kRadius}};
  const float alone = centre(renderer->render(request));
  EXPECT_NEAR(alone, kAlbedo * kSky, 0.03 * kAlbedo * kSky) << "A alone under the sky";
  const double hidden = (kRadius / d) * (kRadius / d);  // π·(r/d)² of π
  EXPECT_NEAR(beside, kAlbedo * kSky * (1.0 - hidden), 0.04 * kAlbedo * kSky * (1.0 - hidden))
      << "A's side facing B loses B's projected solid angle";
}

}  // namespace
}  // namespace haarcast::render
