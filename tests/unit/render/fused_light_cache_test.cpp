// FusedLightCache (renderer.h): resolveFrame keeps each object's light in
// its frame while nothing it depends on has turned, and resolves it afresh
// when the light, the object or the ground has.
#include <gtest/gtest.h>

#include <cstddef>
#include <memory>

#include <glm/gtc/matrix_transform.hpp>

#include "haarcast/render/renderer.h"

namespace haarcast::render {
namespace {

RenderOptions smallOptions() {
  RenderOptions o;
  o.width = o.height = 32;
  o.level = 4;
  o.thetaSamples = 4;
  o.sliceSupersampling = 1;
  o.visibility.supersampling = 1;
  o.refine.rounds = 0;
  return o;
}

FrameRequest requestFor(const PreparedScene& p) {
  FrameRequest r;
  r.width = r.height = 32;
  r.camera = p.scene.camera;
  for (const SceneObject& o : p.scene.objects) r.poses.push_back(o.pose);
  return r;
}

// The same objects' lights, value for value.
void expectSameLights(const ResolvedFrame& a, const ResolvedFrame& b, const char* what) {
  ASSERT_EQ(a.objects.size(), b.objects.size()) << what;
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    EXPECT_EQ(a.objects[i].fusedLight.planes, b.objects[i].fusedLight.planes) << what << ", object " << i;
    EXPECT_EQ(a.objects[i].groundFlat, b.objects[i].groundFlat) << what << ", object " << i;
    ASSERT_EQ(a.objects[i].pointLights.size(), b.objects[i].pointLights.size()) << what;
    for (std::size_t k = 0; k < a.objects[i].pointLights.size(); ++k) {
      EXPECT_EQ(a.objects[i].pointLights[k].direction, b.objects[i].pointLights[k].direction) << what << ", object " << i;
      EXPECT_EQ(a.objects[i].pointLights[k].power, b.objects[i].pointLights[k].power) << what << ", object " << i;
    }
  }
}

// The frame as a scene that has never resolved one would give it.
ResolvedFrame uncached(const PreparedScene& p, const RenderOptions& o, const FrameRequest& r) {
  PreparedScene fresh = p;
  fresh.fusedLightCache = std::make_shared<FusedLightCache>();
  return resolveFrame(fresh, o, r);
}

TEST(FusedLightCache, AnUnchangedFrameIsKeptATurnedLightObjectOrGroundIsResolvedAfresh) {
  const RenderOptions o = smallOptions();
  const PreparedScene p = prepareScene(defaultScene(), o);
  ASSERT_TRUE(p.ground.has_value());
  const std::size_t objects = p.objects.size();
  const FrameRequest still = requestFor(p);
  const ResolvedFrame first = resolveFrame(p, o, still);
  EXPECT_EQ(p.fusedLightCache->hits(), 0u);

  // The camera moves, nothing else: every object's light is kept.
  FrameRequest orbit = still;
  orbit.camera.eye = glm::dvec3(1.0, 0.9, 4.6);
  expectSameLights(resolveFrame(p, o, orbit), first, "camera moved");
  EXPECT_EQ(p.fusedLightCache->hits(), objects);

  // The light turns: every object resolves afresh.
  FrameRequest turnedLight = still;
  turnedLight.lightRotation = glm::dmat3(glm::rotate(glm::dmat4(1.0), glm::radians(40.0), glm::dvec3(0.0, 1.0, 0.0)));
  const ResolvedFrame lit = resolveFrame(p, o, turnedLight);
  expectSameLights(lit, uncached(p, o, turnedLight), "light turned");
  EXPECT_NE(lit.objects[0].fusedLight.planes, first.objects[0].fusedLight.planes) << "the turn changes the light";

  // An object turns: its own light changes.
  FrameRequest turnedObject = turnedLight;
  turnedObject.poses[0].rotateDegrees = {0.0, 75.0, 10.0};
  expectSameLights(resolveFrame(p, o, turnedObject), uncached(p, o, turnedObject), "object turned");

  // The ground tilts: what it hides of the others' sky changes.
  FrameRequest tiltedGround = turnedObject;
  tiltedGround.poses[*p.ground].rotateDegrees = {12.0, 0.0, 0.0};
  expectSameLights(resolveFrame(p, o, tiltedGround), uncached(p, o, tiltedGround), "ground tilted");
}

}  // namespace
}  // namespace haarcast::render
