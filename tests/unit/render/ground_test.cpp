// Shadows on a ground and between objects (`fused`'s point lights,
// render/point_lights.h) against the closed form of a Lambert plane under a
// constant sky and a small sun straight overhead, and the ground's placement.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/shared_layout.h"
#include "haarcast/cpu/cpu_renderer.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/render/point_lights.h"
#include "haarcast/render/renderer.h"

namespace haarcast::render {
namespace {

constexpr double kSky = 0.1;     // radiance of the sky, everywhere
constexpr double kSun = 4000.0;  // radiance of the sun
constexpr double kSunDegrees = 3.0;
constexpr double kAlbedo = 0.5;

bool inSun(const glm::dvec3& d) { return d.y > std::cos(kSunDegrees * kPi / 180.0); }

Environment sunAndSky() {
  Environment e;
  e.name = "sun overhead";
  e.radiance = [](const glm::dvec3& d) { return glm::dvec3(inSun(d) ? kSun : kSky); };
  e.maps = [](int level) {
    const SphereMap m = supersampledMap(level, 4, [](const glm::dvec3& d) { return inSun(d) ? kSun : kSky; });
    return std::array<SphereMap, 3>{m, m, m};
  };
  return e;
}

// A unit ball whose centre is 1.5 above a ground at y = 0, looked at from
// above and aside; the frame's centre pixel sees `target` on the ground.
Scene ballOverGround(const glm::dvec3& target) {
  Scene s;
  s.environment = sunAndSky();
  SceneObject ball{"ball", std::make_shared<Mesh>(assets::makeSphere(32)), materialFromSpec("lambert"), {}};
  ball.pose.translate = {0.0, 1.5, 0.0};
  ball.pose.scale = 0.5;
  SceneObject ground{"ground", std::make_shared<Mesh>(assets::makePlane(1.0, 4)), materialFromSpec("lambert"), {}};
  ground.ground = true;
  ground.groundAlbedo = glm::dvec3(kAlbedo);
  ground.material.brdf = makeLambert(ground.groundAlbedo);
  ground.material.cacheKey = "lambert-0.5";
  ground.pose.scale = 20.0;
  s.objects = {ball, ground};
  s.camera.eye = {0.0, 4.0, 4.0};
  s.camera.target = target;
  return s;
}

RenderOptions options() {
  RenderOptions o;
  o.width = o.height = 9;  // odd: the centre pixel's ray goes through the target
  o.level = 5;
  o.thetaSamples = 4;
  o.visibility.supersampling = 1;
  o.environmentBackground = false;
  return o;
}

float centre(const Frame& f) { return f.image.at(f.height / 2, f.width / 2, 0); }

// The sun's power above the sky's, (L_sun − L_sky)·2π(1 − cos r): the
// point light is found on the fine backdrop map (light_split.h), which
// holds the cap to a fraction of a per cent, where a level-5 texel would
// not.
double sunPower() { return (kSun - kSky) * kTwoPi * (1.0 - std::cos(kSunDegrees * kPi / 180.0)); }

TEST(Ground, TakesTheBallsShadowAndIsLitInTheOpen) {
  const RenderOptions o = options();
  // The Lambert plane: ρ = a/π; the sky above it gives a·kSky, the sun
  // overhead a/π·P where it is seen (the sphere's share of the sky above
  // the shadowed point is not taken: fused's map light meets only the
  // object's own visibility).
  const double skyPart = kAlbedo * kSky;
  const double sunPart = kAlbedo / kPi * sunPower();
  ASSERT_GT(sunPart, 10.0 * skyPart) << "the sun dominates";
  const auto shadowed = makeCpuRenderer(ballOverGround({0.0, 0.0, 0.1}), o);
  FrameRequest request;
  request.width = o.width;
  request.height = o.height;
  request.camera = ballOverGround({0.0, 0.0, 0.1}).camera;
  const Frame under = shadowed->render(request);
  // Under the ball the sun is hidden, and so is the ball's share of the
  // sky: a sphere of radius r at distance d, its centre θ from the normal,
  // hides cos θ·(r/d)² of a plane point's cosine-weighted sky
  // (groundSkyOcclusion; 11 % here, 0 before it).
  const glm::dvec3 toBall = glm::dvec3(0.0, 1.5, 0.0) - glm::dvec3(0.0, 0.0, 0.1);
  const double hiddenSky = toBall.y / glm::length(toBall) * 0.25 / glm::dot(toBall, toBall);
  EXPECT_NEAR(centre(under), skyPart * (1.0 - hiddenSky), 0.02 * skyPart * (1.0 - hiddenSky))
      << "the ground under the ball is in its shadow, sun and sky";

  request.camera.target = {2.0, 0.0, 1.0};
  const Frame open = shadowed->render(request);
  EXPECT_NEAR(centre(open), skyPart + sunPart, 0.02 * (skyPart + sunPart)) << "the ground away from the ball is lit";

  // The ball moved aside: its shadow goes with it in the same frame.
  request.camera.target = {0.0, 0.0, 0.1};
  request.poses = {Pose{{0.0, 0.0, 0.0}, {3.0, 1.5, 0.0}, 0.5}, Pose{{0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, 20.0}};
  const Frame moved = shadowed->render(request);
  EXPECT_NEAR(centre(moved), skyPart + sunPart, 0.02 * (skyPart + sunPart));
}

TEST(Ground, ObjectsShadowEachOther) {
  // A second ball above the first hides the sun from the first's top.
  RenderOptions o = options();
  Scene s = ballOverGround({0.0, 1.95, 0.0});
  SceneObject top = s.objects[0];
  top.name = "above";
  top.pose.translate = {0.0, 3.0, 0.0};
  top.pose.scale = 0.3;
  s.objects.insert(s.objects.begin() + 1, top);
  s.camera.eye = {0.0, 2.2, 3.0};  // below the upper ball, looking at the lower one's top
  const auto renderer = makeCpuRenderer(s, o);
  FrameRequest request;
  request.width = o.width;
  request.height = o.height;
  request.camera = s.camera;
  const float hidden = centre(renderer->render(request));
  request.poses = {s.objects[0].pose, Pose{{0.0, 0.0, 0.0}, {4.0, 3.0, 0.0}, 0.3}, s.objects[2].pose};
  const float lit = centre(renderer->render(request));
  EXPECT_GT(lit, 5.0f * hidden) << "hidden " << hidden << ", lit " << lit;
}

// The ground's hidden sky on its grids (point_lights.h GroundSkyGrid): a
// cell whose four corners are ground blends them; a cell an object's
// outline crosses (a corner off the ground) reads the fine grid, traced
// only around it, and a fine cell the outline crosses takes the sample's
// own rays, so that no blend reaches past the outline.
TEST(Ground, TheGridBlendsOpenCellsAndRefinesCellsAnOutlineCrosses) {
  const Mesh plane = assets::makePlane(1.0, 1);
  const RayScene world({Instance{&plane, glm::mat4(1.0f)}});
  SkyOccluders sky;  // no occluders: every grid point hides nothing
  GroundSkyGrid grid(40, 40);
  ASSERT_EQ(groundSkyStep(40, 40), 4);
  ASSERT_EQ(shared::groundSkyFineStep(4u), 2u);
  const std::size_t offGround = 8 * 40 + 8;  // coarse point (2, 2), fine point (4, 4): an object's pixel
  grid.compute(world, sky, [&](std::size_t pixel) -> std::optional<ShadingPoint> {
    if (pixel == offGround) return std::nullopt;
    return ShadingPoint{glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f), 1e-4f};
  }, 1);
  const auto own = [] { return 0.25f; };  // what the sample's own rays would say
  auto at = [&](int x, int y) { return grid.at(static_cast<std::size_t>(y) * 40 + static_cast<std::size_t>(x), own); };
  EXPECT_EQ(at(13, 13), 0.0f) << "the cell (12…16)² is open ground: its corners' blend";
  EXPECT_EQ(at(5, 5), 0.0f) << "the cell (4…8)² is crossed; its fine cell (4…6)² is open ground";
  EXPECT_EQ(at(9, 5), 0.0f) << "the cell (8…12) × (4…8) is crossed; its fine cell (8…10) × (4…6) is open";
  EXPECT_EQ(at(7, 7), 0.25f) << "the fine cell (6…8)² has a corner off the ground";
  EXPECT_EQ(at(9, 9), 0.25f) << "so has the fine cell (8…10)²";
  EXPECT_EQ(at(11, 7), 0.0f) << "the fine cell (10…12) × (6…8) is open";
  // The four crossed cells span pixels 4…11 each way: fine points 2…6 (the
  // points whose fine cells reach them), 5 × 5, and no other.
  EXPECT_EQ(grid.finePointsTraced(), 25u);
}

TEST(Ground, AddGroundPutsAWidePlaneUnderTheObjects) {
  Scene s = defaultScene();
  ASSERT_TRUE(s.objects.back().ground) << "the built-in scene stands on a ground";
  const SceneObject& g = s.objects.back();
  // Its top at the lowest point of the objects, its normal up.
  double lowest = 1e9;
  for (std::size_t k = 0; k + 1 < s.objects.size(); ++k) {
    const glm::dmat4 m = s.objects[k].pose.objectToWorld();
    for (const glm::vec3& p : s.objects[k].mesh->positions) lowest = std::min(lowest, (m * glm::dvec4(glm::dvec3(p), 1.0)).y);
  }
  EXPECT_NEAR(g.pose.translate.y, lowest, 1e-9);
  EXPECT_GT(g.pose.scale, 10.0);
  EXPECT_THROW(addGround(s), std::invalid_argument) << "a second ground";
  Scene empty;
  EXPECT_THROW(addGround(empty), std::invalid_argument);
  Scene one = ballOverGround({});
  one.objects.pop_back();
  EXPECT_THROW(addGround(one, GroundOptions{1.5, 12.0}), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast::render
