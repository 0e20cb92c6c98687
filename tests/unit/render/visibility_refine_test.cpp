// Refining a mesh where its vertices' visibility disagrees: the surface is
// kept (area, original vertices, no T-junction), the new vertices' bits are
// the rays' own, the edges left agree, the blend across triangles comes
// closer to the exact visibility at points inside them, and the cache gives
// back what it stored.
#include "haarcast/render/visibility_refine.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <mutex>
#include <map>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include <glm/geometric.hpp>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/render/renderer.h"
#include "haarcast/render/visibility_cache.h"

#include "../test_files.h"

namespace haarcast {
namespace {

// Two pillars on a slab, one subdivision per face: its slab's vertices lie
// under the pillars and at their feet, the case the blend gets wrong.
Mesh slabWithPillars() {
  Mesh m = assets::makePillars(2, 1);
  if (m.normals.empty()) m.computeNormals();
  return m;
}

VisibilityOptions level4() {
  VisibilityOptions o;
  o.level = 4;
  return o;
}

double area(const Mesh& m) {
  double a = 0.0;
  for (const glm::uvec3& t : m.triangles) {
    const glm::dvec3 p(m.positions[t.x]), q(m.positions[t.y]), r(m.positions[t.z]);
    a += 0.5 * glm::length(glm::cross(q - p, r - p));
  }
  return a;
}

using PositionEdge = std::tuple<float, float, float, float, float, float>;
PositionEdge directed(const glm::vec3& p, const glm::vec3& q) { return {p.x, p.y, p.z, q.x, q.y, q.z}; }

// The mean over `points` random points of the mesh of the cosine-weighted
// hemisphere on which the blended bits differ from the point's own rays.
double blendError(const RayScene& occluders, const Mesh& mesh, const VisibilityBits& bits, const VisibilityOptions& o) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int m = mapSize(o.level);
  std::vector<glm::vec3> directions;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) directions.emplace_back(sphericalToDirection(rowTheta(o.level, i), colPhi(o.level, j)));
  const float shift = o.offset * static_cast<float>(mesh.bounds().radius());
  double sum = 0.0;
  const int points = 400;
  for (int k = 0; k < points; ++k) {
    const glm::uvec3 t = mesh.triangles[std::uniform_int_distribution<std::size_t>(0, mesh.triangles.size() - 1)(rng)];
    float a = u(rng), b = u(rng);
    if (a + b > 1.0f) a = 1.0f - a, b = 1.0f - b;
    const float w[3] = {1.0f - a - b, a, b};
    glm::vec3 p(0.0f), n(0.0f);
    for (int v = 0; v < 3; ++v) p += w[v] * mesh.positions[t[v]], n += w[v] * mesh.normals[t[v]];
    n = glm::normalize(n);
    std::vector<std::uint8_t> blocked(directions.size());
    occluders.occludedFrom(p + n * shift, 0.0f, directions, blocked);
    for (std::size_t i = 0; i < directions.size(); ++i) {
      const float cosine = glm::dot(n, directions[i]);
      if (cosine <= 0.0f) continue;
      float blend = 0.0f;
      for (int v = 0; v < 3; ++v) blend += w[v] * (bits.visible(t[v], i) ? 1.0f : 0.0f);
      sum += std::abs(blend - (blocked[i] ? 0.0f : 1.0f)) * cosine * pixelSolidAngle(o.level, static_cast<int>(i) / m) / kPi;
    }
  }
  return sum / points;
}

TEST(VisibilityRefine, KeepsTheSurfaceAndLeavesNoTJunction) {
  const Mesh mesh = slabWithPillars();
  const RefinedVisibility r = computeRefinedVisibility(mesh, level4(), RefineOptions{});
  ASSERT_GT(r.rounds, 0) << "the slab's vertices disagree";
  ASSERT_GT(r.mesh.positions.size(), mesh.positions.size());
  EXPECT_NEAR(area(r.mesh), area(mesh), 1e-5 * area(mesh));
  for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
    ASSERT_EQ(r.mesh.positions[v], mesh.positions[v]) << v;
    ASSERT_EQ(r.mesh.normals[v], mesh.normals[v]) << v;
  }
  for (std::size_t v = 0; v < r.mesh.normals.size(); ++v) ASSERT_NEAR(glm::length(r.mesh.normals[v]), 1.0f, 1e-5f) << v;
  // The boxes are closed: every edge is walked once each way, across creases
  // too (by position). A T-junction would leave a long edge one way and its
  // two halves the other.
  std::map<PositionEdge, int> walks;
  std::map<PositionEdge, int> original;
  for (const glm::uvec3& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++original[directed(mesh.positions[t[k]], mesh.positions[t[(k + 1) % 3]])];
  for (const glm::uvec3& t : r.mesh.triangles)
    for (int k = 0; k < 3; ++k) ++walks[directed(r.mesh.positions[t[k]], r.mesh.positions[t[(k + 1) % 3]])];
  auto unbalanced = [](const std::map<PositionEdge, int>& w) {
    std::size_t n = 0;
    for (const auto& [e, count] : w) {
      const auto& [a, b, c, d, f, g] = e;
      const auto back = w.find({d, f, g, a, b, c});
      n += back == w.end() || back->second != count ? 1 : 0;
    }
    return n;
  };
  ASSERT_EQ(unbalanced(original), 0u) << "the test mesh itself is closed";
  EXPECT_EQ(unbalanced(walks), 0u);
}

TEST(VisibilityRefine, NewVerticesHaveTheirRaysBitsAndFewEdgesStillDisagree) {
  const Mesh mesh = slabWithPillars();
  RefineOptions refine;
  refine.rounds = 16;
  refine.floor = 1u << 20;  // no budget: refine until the edges agree or reach the shortest
  const RefinedVisibility r = computeRefinedVisibility(mesh, level4(), refine);
  const RayScene occluders({Instance{&mesh}});
  const VisibilityBits again = computeVisibilityBits(occluders, r.mesh, level4());
  ASSERT_EQ(again.pointCount(), r.bits.pointCount());
  ASSERT_EQ(std::memcmp(again.words().data(), r.bits.words().data(), again.storedBytes()), 0);
  // Disagreeing edges (longer than the shortest split) become rare: each
  // round splits them, though a split's new edges may disagree in turn.
  const double shortest = refine.minEdge * mesh.bounds().radius();
  auto disagreeing = [&](const Mesh& m, const VisibilityBits& bits) {
    std::size_t bad = 0, edges = 0;
    for (const glm::uvec3& t : m.triangles) {
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = t[k], b = t[(k + 1) % 3];
        if (glm::length(m.positions[a] - m.positions[b]) <= shortest) continue;
        ++edges;
        const glm::vec3 n = glm::normalize(m.normals[a] + m.normals[b]);
        bad += visibilityDisagreement(bits.point(a), bits.point(b), 4, n) > refine.threshold ? 1 : 0;
      }
    }
    return static_cast<double>(bad) / static_cast<double>(std::max<std::size_t>(edges, 1));
  };
  const double before = disagreeing(mesh, computeVisibilityBits(occluders, mesh, level4()));
  const double after = disagreeing(r.mesh, r.bits);
  EXPECT_GT(before, 0.1);
  EXPECT_LT(after, 0.25 * before) << "disagreeing edges: " << before << " of the original's, " << after
                                  << " of the refined mesh's (" << r.rounds << " rounds, "
                                  << r.mesh.positions.size() << " vertices)";
}

// One progress over the whole computation: the mesh's vertices and each
// round's, against the vertex budget, never going back, ending at the budget.
TEST(VisibilityRefine, ProgressCountsEveryRoundAgainstTheBudgetAndNeverGoesBack) {
  const Mesh mesh = slabWithPillars();
  RefineOptions refine;
  refine.rounds = 3;
  const std::size_t budget = refineVertexBudget(mesh.positions.size(), refine);
  ASSERT_GE(budget, mesh.positions.size());
  std::mutex lock;  // the progress comes from the worker threads
  std::vector<std::pair<std::size_t, std::size_t>> calls;
  const RefinedVisibility r = computeRefinedVisibility(mesh, level4(), refine, [&](std::size_t done, std::size_t total) {
    const std::lock_guard<std::mutex> hold(lock);
    calls.emplace_back(done, total);
  });
  ASSERT_GE(r.rounds, 1) << "the test needs a round that adds vertices";
  ASSERT_FALSE(calls.empty());
  std::size_t backwards = 0, past = 0, highest = 0;
  bool beyondTheMesh = false;
  for (const auto& [done, total] : calls) {
    EXPECT_EQ(total, budget);
    past += done > total ? 1 : 0;
    // Workers report in the order they finish: small steps back within a
    // pass are allowed; a pass restarting from 0 (the old per-round count)
    // is not.
    backwards += done + 64 < highest ? 1 : 0;
    highest = std::max(highest, done);
    beyondTheMesh = beyondTheMesh || done > mesh.positions.size();
  }
  EXPECT_EQ(backwards, 0u) << "the count went back by more than the workers' reordering";
  EXPECT_EQ(past, 0u);
  EXPECT_TRUE(beyondTheMesh) << "a round's vertices count after the mesh's own";
  EXPECT_EQ(calls.back(), std::pair(budget, budget));
}

TEST(VisibilityRefine, TheBlendComesCloserToTheRaysInsideTriangles) {
  const Mesh mesh = slabWithPillars();
  const RayScene occluders({Instance{&mesh}});
  const VisibilityBits coarse = computeVisibilityBits(occluders, mesh, level4());
  const RefinedVisibility r = refineVisibility(occluders, mesh, coarse, level4(), RefineOptions{});
  const double before = blendError(occluders, mesh, coarse, level4());
  const double after = blendError(occluders, r.mesh, r.bits, level4());
  EXPECT_GT(before, 0.02) << "the coarse blend is visibly wrong";
  EXPECT_LT(after, 0.5 * before) << "before " << before << ", after " << after;
}

TEST(VisibilityRefine, ZeroRoundsChangeNothingAndBadOptionsAreRefused) {
  const Mesh mesh = slabWithPillars();
  RefineOptions none;
  none.rounds = 0;
  const RefinedVisibility r = computeRefinedVisibility(mesh, level4(), none);
  EXPECT_EQ(r.rounds, 0);
  EXPECT_EQ(r.mesh.positions.size(), mesh.positions.size());
  EXPECT_EQ(r.mesh.triangles.size(), mesh.triangles.size());
  for (auto bad : {RefineOptions{-1}, RefineOptions{17}, RefineOptions{4, 0.0}, RefineOptions{4, 1.5},
                   RefineOptions{4, 0.04, 0.0}, RefineOptions{4, 0.04, 1.0 / 64, 0.5}}) {
    EXPECT_THROW(checkRefineOptions(bad), std::invalid_argument);
  }
}

TEST(VisibilityRefine, TheCacheGivesBackTheRefinedMeshAndBits) {
  testing::TempDir tmp("haarcast-visibility-refine-test-");
  const Mesh mesh = slabWithPillars();
  VisibilityCacheStatus first, second;
  const RefinedVisibility a = loadOrComputeRefinedVisibility(mesh, level4(), RefineOptions{}, tmp.path().string(), {}, &first);
  const RefinedVisibility b = loadOrComputeRefinedVisibility(mesh, level4(), RefineOptions{}, tmp.path().string(), {}, &second);
  EXPECT_FALSE(first.hit);
  EXPECT_TRUE(first.written) << first.error;
  EXPECT_TRUE(second.hit) << second.reason;
  EXPECT_EQ(a.rounds, b.rounds);
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.normals, b.mesh.normals);
  EXPECT_EQ(a.mesh.triangles, b.mesh.triangles);
  ASSERT_EQ(a.bits.storedBytes(), b.bits.storedBytes());
  EXPECT_EQ(std::memcmp(a.bits.words().data(), b.bits.words().data(), a.bits.storedBytes()), 0);
  // Other refinement options are another file.
  RefineOptions other;
  other.threshold = 0.1;
  VisibilityCacheStatus third;
  (void)loadOrComputeRefinedVisibility(mesh, level4(), other, tmp.path().string(), {}, &third);
  EXPECT_FALSE(third.hit);
}

// prepareScene refines `fused`'s meshes, and draws them unrefined where the
// refinement could pass the operator's visibility memory limit.
TEST(VisibilityRefine, PrepareSceneRefinesWithinTheVisibilityLimit) {
  render::Scene scene;
  scene.environment = render::sunsEnvironment();
  scene.objects.push_back({"pillars", std::make_shared<Mesh>(slabWithPillars()), render::materialFromSpec("lambert"), {}});
  render::RenderOptions o;
  o.level = 4;
  o.method = RotationMethod::Fused;
  const std::size_t original = scene.objects[0].mesh->positions.size();
  EXPECT_GT(render::prepareScene(scene, o).objects[0].mesh->positions.size(), original);
  // Room for the mesh, not for the refinement's bound (the floor's vertices).
  o.sceneLimits.maxVisibilityBytes = 4 * visibilityWordsPerPoint(4) * (o.refine.floor - 1);
  EXPECT_EQ(render::prepareScene(scene, o).objects[0].mesh->positions.size(), original);
}

}  // namespace
}  // namespace haarcast
