// RayScene (Embree) and per-vertex visibility, on meshes built here: an
// icosphere (closed, convex) and a square floor.
#include "haarcast/render/visibility.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <thread>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "haarcast/core/brdf_slices.h"
#include "haarcast/render/embree_scene.h"

namespace haarcast {
namespace {

// Icosphere: an icosahedron, each triangle split in four `subdivisions`
// times, vertices pushed onto the sphere. Shared vertices, outward winding,
// exact radial normals.
Mesh icosphere(int subdivisions, float radius = 1.0f, glm::vec3 centre = glm::vec3(0.0f)) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<glm::vec3> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                              {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (glm::vec3& v : p) v = glm::normalize(v);
  std::vector<glm::uvec3> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                               {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                               {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                               {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<unsigned, unsigned>, unsigned> midpoints;
    auto mid = [&](unsigned a, unsigned b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoints.find(key);
      if (it != midpoints.end()) return it->second;
      p.push_back(glm::normalize(p[a] + p[b]));
      const auto index = static_cast<unsigned>(p.size() - 1);
      midpoints.emplace(key, index);
      return index;
    };
    std::vector<glm::uvec3> next;
    for (const glm::uvec3& tri : f) {
      const unsigned ab = mid(tri.x, tri.y), bc = mid(tri.y, tri.z), ca = mid(tri.z, tri.x);
      next.push_back({tri.x, ab, ca});
      next.push_back({tri.y, bc, ab});
      next.push_back({tri.z, ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  Mesh m;
  m.name = "icosphere";
  m.normals = p;
  for (const glm::vec3& v : p) m.positions.push_back(centre + radius * v);
  m.triangles = f;
  return m;
}

// A square floor at y = 0, half-size `half`, normal +Y, cut into an
// (2k)×(2k) grid so that vertex `floorCentre(k)` sits at the origin.
Mesh floorMesh(float half, unsigned k = 2) {
  Mesh m;
  m.name = "floor";
  const unsigned n = 2 * k + 1;  // vertices per side
  for (unsigned i = 0; i < n; ++i) {
    for (unsigned j = 0; j < n; ++j) {
      const float x = -half + 2.0f * half * static_cast<float>(j) / static_cast<float>(n - 1);
      const float z = -half + 2.0f * half * static_cast<float>(i) / static_cast<float>(n - 1);
      m.positions.push_back({x, 0.0f, z});
      m.normals.push_back({0.0f, 1.0f, 0.0f});
    }
  }
  for (unsigned i = 0; i + 1 < n; ++i) {
    for (unsigned j = 0; j + 1 < n; ++j) {
      const unsigned a = i * n + j, b = a + 1, c = a + n, d = c + 1;
      // (c − a) × (b − a) = +Z × +X = +Y: faces up.
      m.triangles.push_back({a, c, b});
      m.triangles.push_back({b, c, d});
    }
  }
  return m;
}
unsigned floorCentre(unsigned k = 2) { return k * (2 * k + 1) + k; }

Mesh merged(const Mesh& a, const Mesh& b) {
  Mesh m = a;
  m.name = a.name + "+" + b.name;
  const auto base = static_cast<unsigned>(a.positions.size());
  m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
  m.normals.insert(m.normals.end(), b.normals.begin(), b.normals.end());
  for (const glm::uvec3& t : b.triangles) m.triangles.push_back(t + glm::uvec3(base));
  return m;
}

// ∫ (1 − V) dω over the upper hemisphere (θ < π/2: the first M/2 rows).
double occludedAbove(const SphereMap& v) {
  double sum = 0.0;
  for (int row = 0; row < v.size() / 2; ++row) {
    for (int col = 0; col < v.size(); ++col) sum += (1.0 - v.at(row, col)) * pixelSolidAngle(v.level(), row);
  }
  return sum;
}

// ---------------------------------------------------------------- RayScene

TEST(RayScene, IntersectReportsDistanceBarycentricsAndNormal) {
  const Mesh sphere = icosphere(3);
  const RayScene scene({Instance{&sphere}});
  const Ray ray{{0.3f, 0.2f, 5.0f}, {0.0f, 0.0f, -1.0f}};
  const std::optional<Hit> hit = scene.intersect(ray);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->object, 0u);
  ASSERT_LT(hit->triangle, sphere.triangles.size());
  // The hit point, from t and from the barycentrics, agree.
  const glm::uvec3 tri = sphere.triangles[hit->triangle];
  const glm::vec3 fromBary = (1.0f - hit->u - hit->v) * sphere.positions[tri.x] + hit->u * sphere.positions[tri.y] +
                             hit->v * sphere.positions[tri.z];
  const glm::vec3 fromT = ray.origin + hit->t * ray.direction;
  EXPECT_NEAR(glm::distance(fromBary, fromT), 0.0f, 1e-5f);
  // On an inscribed polyhedron, just inside the unit sphere.
  EXPECT_NEAR(glm::length(fromT), 1.0f, 0.01f);
  EXPECT_GT(glm::dot(hit->geometricNormal, glm::normalize(fromT)), 0.99f);  // outward winding
  EXPECT_NEAR(glm::length(hit->geometricNormal), 1.0f, 1e-5f);
}

TEST(RayScene, MissesAndRespectsTheRaySegment) {
  const Mesh sphere = icosphere(2);
  const RayScene scene({Instance{&sphere}});
  EXPECT_FALSE(scene.intersect(Ray{{0.0f, 5.0f, 0.0f}, {0.0f, 1.0f, 0.0f}}));
  EXPECT_FALSE(scene.occluded(Ray{{0.0f, 5.0f, 0.0f}, {0.0f, 1.0f, 0.0f}}));
  // The sphere is 4 away: a segment of length 3 does not reach it.
  EXPECT_FALSE(scene.occluded(Ray{{0.0f, 5.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, 0.0f, 3.0f}));
  EXPECT_TRUE(scene.occluded(Ray{{0.0f, 5.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, 0.0f, 4.5f}));
  // Starting past the far side: nothing.
  EXPECT_FALSE(scene.occluded(Ray{{0.0f, 5.0f, 0.0f}, {0.0f, -1.0f, 0.0f}, 6.5f}));
}

TEST(RayScene, InstancesAreNamedAndPlacedByTheirTransforms) {
  const Mesh sphere = icosphere(2, 0.5f);
  const Mesh floor = floorMesh(4.0f);
  // Object 0: the sphere at x = +2. Object 1: the same sphere (shared BVH) at
  // x = −2. Object 2: the floor turned upright (about X by −90°), so its +Y
  // normal points to +Z, then moved to z = −3.
  const glm::mat4 upright =
      glm::rotate(glm::translate(glm::mat4(1.0f), {0.0f, 0.0f, -3.0f}), glm::radians(90.0f), {1.0f, 0.0f, 0.0f});
  const RayScene scene({Instance{&sphere, glm::translate(glm::mat4(1.0f), {2.0f, 0.0f, 0.0f})},
                        Instance{&sphere, glm::translate(glm::mat4(1.0f), {-2.0f, 0.0f, 0.0f})},
                        Instance{&floor, upright}});
  EXPECT_EQ(scene.objectCount(), 3u);
  const auto a = scene.intersect(Ray{{2.0f, 0.0f, 5.0f}, {0.0f, 0.0f, -1.0f}});
  const auto b = scene.intersect(Ray{{-2.0f, 0.0f, 5.0f}, {0.0f, 0.0f, -1.0f}});
  const auto c = scene.intersect(Ray{{0.0f, 0.0f, 5.0f}, {0.0f, 0.0f, -1.0f}});
  ASSERT_TRUE(a && b && c);
  EXPECT_EQ(a->object, 0u);
  EXPECT_EQ(b->object, 1u);
  EXPECT_EQ(c->object, 2u);
  EXPECT_NEAR(a->t, 4.5f, 0.01f);
  EXPECT_NEAR(c->t, 8.0f, 1e-4f);
  // The floor's normal, carried by the instance's rotation into the world.
  EXPECT_NEAR(c->geometricNormal.z, 1.0f, 1e-5f);
}

TEST(RayScene, SetTransformMovesAnObject) {
  const Mesh sphere = icosphere(2);
  RayScene scene({Instance{&sphere}});
  const Ray ray{{0.0f, 0.0f, 5.0f}, {0.0f, 0.0f, -1.0f}};
  ASSERT_TRUE(scene.occluded(ray));
  scene.setTransform(0, glm::translate(glm::mat4(1.0f), {0.0f, 10.0f, 0.0f}));
  EXPECT_FALSE(scene.occluded(ray));
  EXPECT_TRUE(scene.occluded(Ray{{0.0f, 10.0f, 5.0f}, {0.0f, 0.0f, -1.0f}}));
  // Back at the identity (where occlusion skips the instance level).
  scene.setTransform(0, glm::mat4(1.0f));
  EXPECT_TRUE(scene.occluded(ray));
  EXPECT_FALSE(scene.occluded(Ray{{0.0f, 10.0f, 5.0f}, {0.0f, 0.0f, -1.0f}}));
  EXPECT_THROW(scene.setTransform(1, glm::mat4(1.0f)), std::out_of_range);
}

// One origin's directions as packets of 16 give the single rays' answers:
// for one object at the identity (traced without the instance level), the
// same object moved, and a count that leaves the last packet part full.
TEST(RayScene, OccludedFromAgreesWithSingleRays) {
  const Mesh scene = merged(floorMesh(4.0f), icosphere(2, 0.5f, {0.0f, 1.0f, 0.0f}));
  std::mt19937 rng(11);
  std::normal_distribution<float> g(0.0f, 1.0f);
  std::vector<glm::vec3> directions(1001);
  for (glm::vec3& d : directions) d = glm::normalize(glm::vec3(g(rng), g(rng), g(rng)));
  const glm::mat4 moved = glm::translate(glm::mat4(1.0f), {0.3f, 0.0f, -0.2f});
  for (const glm::mat4& placed : {glm::mat4(1.0f), moved}) {
    const RayScene rays({Instance{&scene, placed}});
    const glm::vec3 origin(0.2f, 0.05f, 0.1f);
    for (float tnear : {0.0f, 0.3f}) {
      std::vector<std::uint8_t> out(directions.size(), 2);
      rays.occludedFrom(origin, tnear, directions, out);
      std::size_t blocked = 0;
      for (std::size_t i = 0; i < directions.size(); ++i) {
        ASSERT_EQ(out[i], rays.occluded(Ray{origin, directions[i], tnear}) ? 1 : 0) << "direction " << i;
        blocked += out[i];
      }
      EXPECT_GT(blocked, directions.size() / 10);  // both answers are seen
      EXPECT_LT(blocked, directions.size() - directions.size() / 10);
    }
  }
  std::vector<std::uint8_t> wrongSize(3);
  EXPECT_THROW(RayScene({Instance{&scene}}).occludedFrom({}, 0.0f, directions, wrongSize), std::invalid_argument);
}

TEST(RayScene, BatchAndThreadsAgreeWithSingleRays) {
  const Mesh sphere = icosphere(3, 0.7f);
  const Mesh floor = floorMesh(3.0f);
  const RayScene scene({Instance{&sphere, glm::translate(glm::mat4(1.0f), {0.0f, 1.0f, 0.0f})}, Instance{&floor}});
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<Ray> rays(3000);
  for (Ray& r : rays) {
    r.origin = {2.0f * u(rng), 0.5f + u(rng), 2.0f * u(rng)};
    r.direction = glm::normalize(glm::vec3(u(rng), u(rng), u(rng)) + glm::vec3(0.0f, 0.0f, 1e-3f));
  }
  std::vector<std::uint8_t> expected(rays.size());
  std::size_t blocked = 0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    expected[i] = scene.occluded(rays[i]) ? 1 : 0;
    blocked += expected[i];
    ASSERT_EQ(scene.intersect(rays[i]).has_value(), expected[i] == 1) << "ray " << i;
  }
  EXPECT_GT(blocked, rays.size() / 10);  // the test sees both answers
  EXPECT_LT(blocked, rays.size() - rays.size() / 10);

  for (bool coherent : {false, true}) {
    std::vector<std::uint8_t> out(rays.size(), 2);
    scene.occludedBatch(rays, out, coherent);
    EXPECT_EQ(out, expected) << "coherent " << coherent;
  }
  // Many threads on one const scene.
  std::vector<std::vector<std::uint8_t>> perThread(4, std::vector<std::uint8_t>(rays.size()));
  {
    std::vector<std::jthread> threads;
    for (std::size_t k = 0; k < perThread.size(); ++k) {
      threads.emplace_back([&, k] {
        for (std::size_t i = 0; i < rays.size(); ++i) perThread[k][i] = scene.occluded(rays[i]) ? 1 : 0;
      });
    }
  }
  for (const auto& out : perThread) EXPECT_EQ(out, expected);

  std::vector<std::uint8_t> wrongSize(rays.size() - 1);
  EXPECT_THROW(scene.occludedBatch(rays, wrongSize), std::invalid_argument);
}

TEST(RayScene, IsMovable) {
  const Mesh sphere = icosphere(1);
  RayScene a({Instance{&sphere}});
  RayScene b(std::move(a));
  EXPECT_TRUE(b.occluded(Ray{{0.0f, 0.0f, 5.0f}, {0.0f, 0.0f, -1.0f}}));
  RayScene c({Instance{&sphere, glm::translate(glm::mat4(1.0f), {0.0f, 10.0f, 0.0f})}});
  c = std::move(b);
  EXPECT_TRUE(c.occluded(Ray{{0.0f, 0.0f, 5.0f}, {0.0f, 0.0f, -1.0f}}));
}

TEST(RayScene, RefusesBadInputBeforeEmbree) {
  Mesh bad = icosphere(0);
  bad.triangles.push_back({0u, 1u, 99u});  // past the 12 vertices
  EXPECT_THROW(RayScene({Instance{&bad}}), std::invalid_argument);
  EXPECT_THROW(RayScene(std::vector<Instance>{}), std::invalid_argument);
  EXPECT_THROW(RayScene({Instance{nullptr}}), std::invalid_argument);
  const Mesh sphere = icosphere(0);
  glm::mat4 projective(1.0f);
  projective[2][3] = 1.0f;
  EXPECT_THROW(RayScene({Instance{&sphere, projective}}), std::invalid_argument);
  EXPECT_THROW(RayScene({Instance{&sphere, glm::mat4(0.0f)}}), std::invalid_argument);
  glm::mat4 nan(1.0f);
  nan[3][0] = std::nanf("");
  EXPECT_THROW(RayScene({Instance{&sphere, nan}}), std::invalid_argument);
}

// -------------------------------------------------------------- visibility

TEST(Visibility, PointMapIsThePixelMeanOfOcclusionQueries) {
  // A pixel means what a BRDF-slice pixel means: core's supersampledMap of
  // the occlusion query, to the bit.
  const Mesh sphere = icosphere(2, 0.5f, {0.0f, 2.0f, 0.0f});
  const Mesh floor = floorMesh(4.0f);
  const Mesh scene = merged(floor, sphere);
  const RayScene rays({Instance{&scene}});
  const glm::vec3 origin(0.1f, 0.01f, -0.2f);
  for (int s : {1, 2, 3}) {
    const SphereMap batched = pointVisibilityMap(rays, origin, 4, s);
    const SphereMap single = supersampledMap(4, s, [&](const glm::dvec3& d) {
      return rays.occluded(Ray{origin, glm::vec3(d)}) ? 0.0 : 1.0;
    });
    for (std::size_t i = 0; i < batched.pixelCount(); ++i) {
      ASSERT_EQ(batched.values()[i], single.values()[i]) << "s " << s << " pixel " << i;
    }
  }
}

TEST(Visibility, ConvexSphereSeesItsUpperHemisphere) {
  // 642 vertices, 8° between neighbours: a face around a vertex falls below
  // its tangent plane by at most ~5° (0.09 in cos), and every direction of a
  // level-5 pixel lies within 0.11 rad of its centre. So a pixel whose centre
  // is more than 0.2 off the tangent plane (in cos) is all in or all out.
  const Mesh sphere = icosphere(3);
  VisibilityOptions options;
  options.level = 5;
  options.keep = 1024;  // dense: this test is about V, not truncation
  const std::vector<SparseHaar> maps = computeVertexVisibility(sphere, options);
  ASSERT_EQ(maps.size(), sphere.positions.size());
  double lo = 1e9, hi = -1e9;
  for (std::size_t v = 0; v < maps.size(); ++v) {
    const SphereMap map = inverseHaar(maps[v].toDense());
    const double integral = map.integral();
    lo = std::min(lo, integral);
    hi = std::max(hi, integral);
    const glm::dvec3 n(sphere.normals[v]);
    for (int row = 0; row < map.size(); ++row) {
      for (int col = 0; col < map.size(); ++col) {
        const double c = glm::dot(n, sphericalToDirection(rowTheta(5, row), colPhi(5, col)));
        // The inverse transform returns 0 and 1 to within float rounding.
        if (c > 0.2) {
          ASSERT_NEAR(map.at(row, col), 1.0f, 1e-5f) << "vertex " << v << " (" << row << ", " << col << ")";
        } else if (c < -0.2) {
          ASSERT_NEAR(map.at(row, col), 0.0f, 1e-5f) << "vertex " << v << " (" << row << ", " << col << ")";
        }
      }
    }
  }
  // A vertex of a convex polyhedron sees the complement of its tangent cone:
  // a hemisphere plus a band as wide as its faces fall away below the
  // tangent plane. Measured at level 5, s = 2: ∫V/2π in [1.079, 1.095] here,
  // and the excess halves with each subdivision (1.16, 1.08, 1.04, 1.02 for
  // 2 … 5 subdivisions), as the facets' tilt does; a smooth sphere's is 1.
  EXPECT_GT(lo, kTwoPi * 0.99) << "smallest ∫V";
  EXPECT_LT(hi, kTwoPi * 1.12) << "largest ∫V";
  std::printf("convex sphere: ∫V / 2π in [%.4f, %.4f]\n", lo / kTwoPi, hi / kTwoPi);
}

TEST(Visibility, SphereAboveFloorOccludesTheAnalyticCone) {
  // A sphere of radius r centred at height d above a floor vertex hides the
  // cone of half-angle α, sin α = r/d: solid angle 2π(1 − cos α).
  const float r = 0.5f, d = 2.0f;
  const Mesh sphere = icosphere(4, r, {0.0f, d, 0.0f});
  const Mesh floor = floorMesh(6.0f);
  const Mesh scene = merged(floor, sphere);
  const double alpha = std::asin(static_cast<double>(r) / d);
  const double cone = kTwoPi * (1.0 - std::cos(alpha));

  VisibilityOptions options;
  options.level = 5;
  options.keep = 1024;
  const RayScene rays({Instance{&scene}});
  const SphereMap map = vertexVisibilityMap(rays, scene, floorCentre(), options);
  // The exact cone, sampled as the visibility is (the same s×s directions and
  // weights per pixel): what the map should be but for the icosphere's facets.
  const SphereMap exact = supersampledMap(5, options.supersampling, [&](const glm::dvec3& w) {
    return w.y < 0.0 || w.y > std::cos(alpha) ? 0.0 : 1.0;
  });
  double worst = 0.0;
  for (std::size_t i = 0; i < map.pixelCount(); ++i) {
    worst = std::max(worst, static_cast<double>(std::abs(map.values()[i] - exact.values()[i])));
  }
  const double occluded = occludedAbove(map);
  const double sampled = occludedAbove(exact);
  std::printf("cone: occluded %.5f sr, sampled cone %.5f sr, analytic %.5f sr; worst pixel %.3f\n", occluded,
              sampled, cone, worst);
  // Facets flip at most one sample of a pixel on the cone's edge, and the
  // ray-cast map matches the sampled cone to 1%.
  EXPECT_LE(worst, 0.5);
  EXPECT_NEAR(occluded / sampled, 1.0, 0.01);
  // Against the continuous cone, the level-5, s = 2 grid itself is off: the
  // edge at α = 14.48° falls just past a row of samples (every 2.81°), so the
  // sampled cone is 5.6% small. That is the resolution, not the rays.
  EXPECT_NEAR(occluded / cone, 1.0, 0.07);
  // Below the floor, nothing escapes (bar grazing rays past its edge).
  double below = 0.0;
  for (int row = map.size() / 2; row < map.size(); ++row) {
    for (int col = 0; col < map.size(); ++col) below += map.at(row, col) * pixelSolidAngle(5, row);
  }
  EXPECT_LT(below, 1e-3);

  // The same through the scene overload: floor and sphere as two objects.
  const Mesh ball = icosphere(4, r);
  const RayScene two({Instance{&floor}, Instance{&ball, glm::translate(glm::mat4(1.0f), {0.0f, d, 0.0f})}});
  const std::vector<SparseHaar> floorMaps = computeVertexVisibility(two, floor, options);
  const SphereMap again = inverseHaar(floorMaps[floorCentre()].toDense());
  EXPECT_NEAR(occludedAbove(again), occluded, 1e-4);
}

// fused's bits are the single-ray map (s = 1) of each vertex, bit for bit,
// wherever a ray was cast; the directions skipped far below the tangent
// plane are 0.
TEST(Visibility, BitsAreTheOneRayMapOfEachVertex) {
  const Mesh floor = floorMesh(6.0f);
  const Mesh ball = icosphere(3, 0.5f);
  const RayScene two({Instance{&floor}, Instance{&ball, glm::translate(glm::mat4(1.0f), {0.0f, 2.0f, 0.0f})}});
  VisibilityOptions options;
  options.level = 5;
  options.supersampling = 1;
  const VisibilityBits bits = computeVisibilityBits(two, floor, options);
  ASSERT_EQ(bits.pointCount(), floor.positions.size());
  std::size_t differing = 0, shadowed = 0;
  for (std::size_t v = 0; v < floor.positions.size(); ++v) {
    const SphereMap map = vertexVisibilityMap(two, floor, v, options);
    const int m = map.size();
    for (std::size_t i = 0; i < map.pixelCount(); ++i) {
      const glm::dvec3 d = sphericalToDirection(rowTheta(5, static_cast<int>(i) / m), colPhi(5, static_cast<int>(i) % m));
      if (d.y < -std::sin(kBitsSkipBelowDegrees * kPi / 180.0)) {
        // Not traced (past the floor's edge a ray would escape): occluded.
        differing += bits.visible(v, i) ? 1 : 0;
        continue;
      }
      differing += (map.values()[i] != 0.0f) != bits.visible(v, i) ? 1 : 0;
      shadowed += map.values()[i] == 0.0f && i < map.pixelCount() / 2 ? 1 : 0;
    }
  }
  EXPECT_EQ(differing, 0u);
  EXPECT_GT(shadowed, 0u) << "the sphere shadows the floor's upper hemisphere somewhere";
  // And the mesh-alone overload: a convex sphere sees its upper hemisphere.
  const Mesh sphere = icosphere(3, 1.0f);
  const VisibilityBits own = computeVisibilityBits(sphere, options);
  const std::size_t top = 0;  // icosphere vertex 0 lies well above the equator
  const SphereMap map = own.map(top);
  double seen = 0.0;
  for (int row = 0; row < map.size(); ++row)
    for (int col = 0; col < map.size(); ++col) seen += map.at(row, col) * pixelSolidAngle(5, row);
  const glm::vec3 n = glm::normalize(sphere.positions[top]);
  double hemisphere = 0.0;
  for (int row = 0; row < map.size(); ++row)
    for (int col = 0; col < map.size(); ++col)
      hemisphere += glm::dot(glm::vec3(sphericalToDirection(rowTheta(5, row), colPhi(5, col))), n) > 0.0f
                        ? pixelSolidAngle(5, row) : 0.0;
  EXPECT_NEAR(seen / hemisphere, 1.0, 0.08);
}

TEST(Visibility, KeepingEveryCoefficientIsTheDenseMap) {
  const Mesh sphere = icosphere(2, 0.5f, {0.0f, 1.0f, 0.0f});
  const Mesh scene = merged(floorMesh(3.0f), sphere);
  VisibilityOptions options;
  options.level = 4;
  options.keep = 256;  // = N at level 4
  const std::vector<SparseHaar> maps = computeVertexVisibility(scene, options);
  const RayScene rays({Instance{&scene}});
  for (std::size_t v = 0; v < scene.positions.size(); ++v) {
    const HaarMap dense = forwardHaar(vertexVisibilityMap(rays, scene, v, options));
    const HaarMap kept = maps[v].toDense();
    ASSERT_EQ(maps[v].level, 4);
    for (std::size_t i = 0; i < dense.coefficientCount(); ++i) ASSERT_EQ(kept[i], dense[i]) << "vertex " << v;
  }
  // Truncated: at most `keep` terms, and the largest of them.
  options.keep = 16;
  const std::vector<SparseHaar> truncated = computeVertexVisibility(scene, options);
  for (std::size_t v = 0; v < scene.positions.size(); ++v) {
    ASSERT_LE(truncated[v].size(), 16u);
    const SparseHaar expected = keepLargest(maps[v].toDense(), 16);
    EXPECT_EQ(truncated[v].index, expected.index) << "vertex " << v;
  }
}

TEST(Visibility, ComputesNormalsWhenTheMeshHasNone) {
  Mesh sphere = icosphere(1);
  VisibilityOptions options;
  options.level = 3;
  options.keep = 64;
  const std::vector<SparseHaar> withNormals = computeVertexVisibility(sphere, options);
  sphere.normals.clear();
  const std::vector<SparseHaar> without = computeVertexVisibility(sphere, options);
  ASSERT_EQ(without.size(), withNormals.size());
  // Area-weighted face normals of an icosphere are close to the radial ones;
  // the upper hemisphere is visible either way.
  for (const SparseHaar& m : without) EXPECT_GT(inverseHaar(m.toDense()).integral(), kTwoPi * 0.95);
  // The scene overload insists on normals.
  const RayScene rays({Instance{&sphere}});
  EXPECT_THROW(computeVertexVisibility(rays, sphere, options), std::invalid_argument);
}

TEST(Visibility, ProgressReachesTotalOnTheCallingThread) {
  const Mesh sphere = icosphere(2);
  VisibilityOptions options;
  options.level = 3;
  std::vector<std::size_t> seen;
  const std::thread::id caller = std::this_thread::get_id();
  bool otherThread = false;
  computeVertexVisibility(sphere, options, [&](std::size_t done, std::size_t total) {
    EXPECT_EQ(total, sphere.positions.size());
    otherThread |= std::this_thread::get_id() != caller;
    seen.push_back(done);
  });
  ASSERT_FALSE(seen.empty());
  EXPECT_FALSE(otherThread);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_EQ(seen.back(), sphere.positions.size());

  // An exception from the callback stops the work and reaches the caller.
  EXPECT_THROW(computeVertexVisibility(sphere, options,
                                       [](std::size_t, std::size_t) { throw std::runtime_error("cancelled"); }),
               std::runtime_error);
}

TEST(Visibility, BadOptionsAndMeshesThrow) {
  const Mesh sphere = icosphere(0);
  auto with = [](auto change) {
    VisibilityOptions o;
    o.level = 2;
    change(o);
    return o;
  };
  EXPECT_THROW(computeVertexVisibility(sphere, with([](auto& o) { o.level = -1; })), std::invalid_argument);
  EXPECT_THROW(computeVertexVisibility(sphere, with([](auto& o) { o.level = kMaxLevel + 1; })),
               std::invalid_argument);
  EXPECT_THROW(computeVertexVisibility(sphere, with([](auto& o) { o.keep = 0; })), std::invalid_argument);
  EXPECT_THROW(computeVertexVisibility(sphere, with([](auto& o) { o.supersampling = 0; })), std::invalid_argument);
  EXPECT_THROW(computeVertexVisibility(sphere, with([](auto& o) { o.supersampling = 65; })), std::invalid_argument);
  EXPECT_THROW(computeVertexVisibility(sphere, with([](auto& o) { o.offset = -1.0f; })), std::invalid_argument);
  EXPECT_THROW(computeVertexVisibility(sphere, with([](auto& o) { o.offset = std::nanf(""); })),
               std::invalid_argument);

  Mesh bad = sphere;
  bad.triangles.push_back({0u, 1u, 12u});  // one past the 12 vertices
  EXPECT_THROW(computeVertexVisibility(bad, with([](auto&) {})), std::invalid_argument);
  const RayScene rays({Instance{&sphere}});
  EXPECT_THROW(vertexVisibilityMap(rays, sphere, 12, with([](auto&) {})), std::out_of_range);
  EXPECT_THROW(pointVisibilityMap(rays, glm::vec3(0.0f), 2, 1, -1.0f), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast
