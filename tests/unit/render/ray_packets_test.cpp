// RayScene's packets (intersectFrom, occludedToward) and the batched point
// light masks built on them give what the single rays give, ray by ray; and
// every packet call returns whatever the calling thread's stack held before.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/render/point_lights.h"

namespace haarcast {
namespace {

// A sphere standing on a plane and a second sphere beside it, turned and
// moved: instances at and away from the identity, hits and misses.
struct World {
  Mesh sphere = assets::makeSphere(24);
  Mesh plane = assets::makePlane(3.0, 4);
  RayScene rays{{Instance{&plane},
                 Instance{&sphere, glm::translate(glm::mat4(1.0f), {-0.6f, 0.5f, 0.0f}) * glm::scale(glm::mat4(1.0f), glm::vec3(0.5f))},
                 Instance{&sphere, glm::translate(glm::mat4(1.0f), {0.7f, 0.4f, 0.2f}) *
                                       glm::rotate(glm::mat4(1.0f), 0.7f, {0.3f, 1.0f, 0.1f}) * glm::scale(glm::mat4(1.0f), glm::vec3(0.4f))}}};
};

TEST(RayPackets, IntersectFromGivesEachSingleRaysHit) {
  const World w;
  const glm::vec3 eye(0.0f, 1.2f, 4.0f);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-0.45f, 0.45f);
  // 1001 rays: the last packet part full; most toward the objects.
  std::vector<glm::vec3> directions(1001);
  for (glm::vec3& d : directions) d = glm::normalize(glm::vec3(u(rng), u(rng) - 0.25f, -1.0f));
  std::vector<std::optional<Hit>> hits(directions.size());
  w.rays.intersectFrom(eye, 0.0f, directions, hits);
  std::size_t hit = 0;
  for (std::size_t i = 0; i < directions.size(); ++i) {
    const std::optional<Hit> one = w.rays.intersect(Ray{eye, directions[i]});
    ASSERT_EQ(hits[i].has_value(), one.has_value()) << "ray " << i;
    if (!one) continue;
    ++hit;
    EXPECT_EQ(hits[i]->object, one->object) << "ray " << i;
    EXPECT_EQ(hits[i]->triangle, one->triangle) << "ray " << i;
    EXPECT_NEAR(hits[i]->t, one->t, 1e-5f * one->t) << "ray " << i;
    EXPECT_NEAR(hits[i]->u, one->u, 1e-5f) << "ray " << i;
    EXPECT_NEAR(hits[i]->v, one->v, 1e-5f) << "ray " << i;
    EXPECT_NEAR(glm::dot(hits[i]->geometricNormal, one->geometricNormal), 1.0f, 1e-6f) << "ray " << i;
  }
  EXPECT_GT(hit, directions.size() / 2);  // both answers are seen
  EXPECT_LT(hit, directions.size());
  std::vector<std::optional<Hit>> wrongSize(3);
  EXPECT_THROW(w.rays.intersectFrom(eye, 0.0f, directions, wrongSize), std::invalid_argument);
}

TEST(RayPackets, OccludedTowardGivesEachSingleRaysAnswer) {
  const World w;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  std::vector<glm::vec3> origins(1001);
  for (glm::vec3& o : origins) o = glm::vec3(u(rng), 0.01f, u(rng));  // just above the plane
  for (const glm::vec3& toward : {glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f)), glm::normalize(glm::vec3(-1.0f, 0.4f, 0.0f))}) {
    for (float tnear : {0.0f, 0.2f}) {
      std::vector<std::uint8_t> out(origins.size(), 2);
      w.rays.occludedToward(origins, toward, tnear, out);
      std::size_t blocked = 0;
      for (std::size_t i = 0; i < origins.size(); ++i) {
        ASSERT_EQ(out[i], w.rays.occluded(Ray{origins[i], toward, tnear}) ? 1 : 0) << "origin " << i;
        blocked += out[i];
      }
      EXPECT_GT(blocked, 0u);  // both answers are seen
      EXPECT_LT(blocked, origins.size());
    }
  }
  std::vector<std::uint8_t> wrongSize(3);
  EXPECT_THROW(w.rays.occludedToward(origins, glm::vec3(0.0f, 1.0f, 0.0f), 0.0f, wrongSize), std::invalid_argument);
}

TEST(RayPackets, PointLightMasksAreEachPointsMask) {
  const World w;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  std::normal_distribution<float> g(0.0f, 1.0f);
  // Points on the plane, each with a normal that faces some lights and not others.
  std::vector<render::ShadingPoint> points(517);
  for (render::ShadingPoint& p : points) {
    p.position = glm::vec3(u(rng), 0.0f, u(rng));
    p.normal = glm::normalize(glm::vec3(0.6f * g(rng), 1.0f, 0.6f * g(rng)));
    p.shift = 1e-3f;
  }
  const std::vector<glm::vec3> lights{glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f)), glm::normalize(glm::vec3(-1.0f, 0.3f, 0.0f)),
                                      glm::normalize(glm::vec3(0.9f, 0.15f, -0.4f))};
  std::vector<std::uint32_t> masks(points.size(), 0xdeadbeefu);
  render::pointLightMasks(w.rays, points, lights, masks);
  std::vector<std::size_t> seen(lights.size(), 0);
  for (std::size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(masks[i], render::pointLightMask(w.rays, points[i], lights)) << "point " << i;
    for (std::size_t k = 0; k < lights.size(); ++k) seen[k] += (masks[i] >> k) & 1u;
  }
  for (std::size_t k = 0; k < lights.size(); ++k) {
    EXPECT_GT(seen[k], 0u) << "light " << k;
    EXPECT_LT(seen[k], points.size()) << "light " << k;
  }
}

// A ground point's rays that miss every object's bounding sphere are not
// traced: the masks are the traced ones bit for bit, and most rays from the
// open plane are let through untraced (so the test sees both answers).
TEST(RayPackets, AGroundPointsRaysThatMissTheObjectsSpheresAreLitUntraced) {
  const World w;
  // The two spheres' instances as posed (unit sphere, centre 0, radius 1 before the pose).
  const std::vector<glm::vec4> blockers{{-0.6f, 0.5f, 0.0f, 0.5f}, {0.7f, 0.4f, 0.2f, 0.4f}};
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.5f, 1.5f);
  std::vector<render::ShadingPoint> points(613);
  std::vector<std::uint8_t> onGround(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    // Every third point a sphere's (its own sphere may block it: traced).
    if (i % 3 == 2) {
      const glm::vec3 n = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)));
      points[i] = {glm::vec3(-0.6f, 0.5f, 0.0f) + 0.5f * n, n, 1e-3f};
    } else {
      points[i] = {glm::vec3(u(rng), 0.0f, u(rng)), glm::vec3(0.0f, 1.0f, 0.0f), 1e-3f};
      onGround[i] = 1;
    }
  }
  const std::vector<glm::vec3> lights{glm::normalize(glm::vec3(0.3f, 1.0f, 0.2f)), glm::normalize(glm::vec3(-1.0f, 0.3f, 0.0f)),
                                      glm::normalize(glm::vec3(0.9f, 0.15f, -0.4f))};
  std::vector<std::uint32_t> traced(points.size()), culled(points.size());
  render::pointLightMasks(w.rays, points, lights, traced);
  render::pointLightMasks(w.rays, points, lights, culled, render::GroundRays{blockers, onGround});
  std::size_t untraced = 0, shadowed = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    ASSERT_EQ(culled[i], traced[i]) << "point " << i;
    if (!onGround[i]) continue;
    const std::uint32_t open =
        render::raysMissingSpheres(points[i].position + points[i].normal * points[i].shift, lights, blockers);
    for (std::size_t k = 0; k < lights.size(); ++k) {
      if ((open >> k) & 1u) ++untraced;
      else if (!((traced[i] >> k) & 1u)) ++shadowed;
    }
  }
  EXPECT_GT(untraced, points.size());  // most of the ground's rays
  EXPECT_GT(shadowed, 10u);            // and shadows on it, traced
  // Rays through a sphere, from inside one, away from both; grazing: the
  // closest approach just inside the radius is not let through.
  const std::vector<glm::vec3> along{{0.0f, 0.0f, -1.0f}, {0.0f, 0.0f, 1.0f}};
  EXPECT_EQ(render::raysMissingSpheres({-0.6f, 0.0f, 2.0f}, along, blockers), 0b10u);
  EXPECT_EQ(render::raysMissingSpheres({-0.6f, 0.5f, 0.3f}, along, blockers), 0u);
  EXPECT_EQ(render::raysMissingSpheres({-0.6f, 0.5f, 2.0f}, along, blockers), 0b10u);
  EXPECT_EQ(render::raysMissingSpheres({-0.6f + 0.4995f, 0.5f, 2.0f}, along, blockers), 0b10u);
  EXPECT_EQ(render::raysMissingSpheres({-0.6f + 0.4995f, 0.5f, -2.0f}, along, blockers), 0b01u);
}

// Fills `bytes` of the stack below the caller with `value`: what a deeper
// call that ran earlier on this thread may have left there. volatile, so the
// stores are made; noinline, so the frame lies where the next call's will.
[[gnu::noinline]] void fillStackBelow(unsigned char value) {
  constexpr std::size_t bytes = std::size_t{1} << 17;  // Embree's packet frames take about 50 KB
  volatile unsigned char buffer[bytes];
  for (std::size_t i = 0; i < bytes; ++i) buffer[i] = value;
  static_cast<void>(buffer[0]);  // a volatile read: the buffer is used
}

// Embree's coherent occlusion path for packets of 16 reads part of a mask
// from stack memory it never wrote (embree_scene.cpp, occludedPackets): on
// an AVX-512 CPU a non-zero byte there made rtcOccluded16 loop for ever on
// a scene with instances. Each call here runs in a child process (a death
// test) that SIGALRM ends after 10 s, so a spin fails the test instead of
// holding it; the answers are checked against single rays as well. Where
// Embree runs a packet of 16 as two of 8 (no AVX-512) the old path passed too.
TEST(RayPackets, OcclusionReturnsWhateverTheStackHolds) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const World w;
  // One ground point's directions toward a sphere's cone, and ground points toward one light: the
  // two packet calls the ground's hidden sky and the point lights make.
  const glm::vec3 origin(-0.9f, 0.01f, 0.4f);
  std::vector<glm::vec3> directions;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 8; ++j)
      directions.push_back(glm::normalize(glm::vec3(0.05f * static_cast<float>(j) + 0.1f, 0.3f + 0.1f * static_cast<float>(i), -0.6f)));
  std::vector<glm::vec3> origins;
  for (int i = 0; i < 32; ++i) origins.push_back(glm::vec3(-1.4f + 0.05f * static_cast<float>(i), 0.01f, 0.1f));
  const glm::vec3 toward = glm::normalize(glm::vec3(0.4f, 0.5f, 0.0f));
  std::vector<std::uint8_t> fromExpected(directions.size()), towardExpected(origins.size());
  for (std::size_t i = 0; i < directions.size(); ++i) fromExpected[i] = w.rays.occluded(Ray{origin, directions[i]}) ? 1 : 0;
  for (std::size_t i = 0; i < origins.size(); ++i) towardExpected[i] = w.rays.occluded(Ray{origins[i], toward}) ? 1 : 0;
  for (const unsigned char value : {0x00, 0x01, 0x80, 0xff}) {
    const auto child = [&] {
      alarm(10);
      std::vector<std::uint8_t> from(directions.size(), 2), along(origins.size(), 2);
      fillStackBelow(value);
      w.rays.occludedFrom(origin, 0.0f, directions, from);
      fillStackBelow(value);
      w.rays.occludedToward(origins, toward, 0.0f, along);
      std::_Exit(from == fromExpected && along == towardExpected ? 0 : 1);
    };
    EXPECT_EXIT(child(), ::testing::ExitedWithCode(0), "")
        << "stack filled with " << static_cast<int>(value) << ": a spin ends by SIGALRM, exit code 1 is a wrong answer";
  }
  std::size_t blocked = 0;
  for (const std::uint8_t b : fromExpected) blocked += b;
  for (const std::uint8_t b : towardExpected) blocked += b;
  EXPECT_GT(blocked, 0u);  // both answers are seen
  EXPECT_LT(blocked, directions.size() + origins.size());
}

}  // namespace
}  // namespace haarcast
