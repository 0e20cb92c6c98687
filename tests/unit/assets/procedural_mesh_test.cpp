// The built-in meshes against their analytic surfaces: area, enclosed volume
// (divergence theorem: V = Σ (a · (b × c))/6 over outward-wound triangles),
// closedness, and unit outward normals. A flipped triangle, a seam that is not
// shared or a normal of the wrong sign each break one of these.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <stdexcept>
#include <utility>

#include <glm/geometric.hpp>

#include "haarcast/assets/procedural_mesh.h"
#include "haarcast/core/sphere_map.h"

namespace haarcast::assets {
namespace {

double area(const Mesh& m) {
  double a = 0.0;
  for (const glm::uvec3& t : m.triangles) {
    const glm::dvec3 p(m.positions[t.x]), q(m.positions[t.y]), r(m.positions[t.z]);
    a += 0.5 * glm::length(glm::cross(q - p, r - p));
  }
  return a;
}

double volume(const Mesh& m) {
  double v = 0.0;
  for (const glm::uvec3& t : m.triangles) {
    const glm::dvec3 p(m.positions[t.x]), q(m.positions[t.y]), r(m.positions[t.z]);
    v += glm::dot(p, glm::cross(q, r)) / 6.0;
  }
  return v;
}

// Closed and consistently oriented: every directed edge (a, b) appears once
// and its twin (b, a) once. Holds for meshes whose vertices are shared.
void expectClosedManifold(const Mesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
  for (const glm::uvec3& t : m.triangles) {
    ++edges[{t.x, t.y}];
    ++edges[{t.y, t.z}];
    ++edges[{t.z, t.x}];
  }
  for (const auto& [edge, count] : edges) {
    ASSERT_EQ(count, 1) << "edge " << edge.first << "→" << edge.second << " is used twice in one direction";
    ASSERT_EQ(edges.count({edge.second, edge.first}), 1u)
        << "edge " << edge.first << "→" << edge.second << " has no twin: the mesh has a hole";
  }
}

// Vertex normals are unit, and every triangle's winding normal points the way
// its vertices' normals do (outward).
void expectUnitOutwardNormals(const Mesh& m) {
  ASSERT_EQ(m.normals.size(), m.positions.size());
  for (std::size_t i = 0; i < m.normals.size(); ++i) {
    ASSERT_NEAR(glm::length(glm::dvec3(m.normals[i])), 1.0, 1e-6) << "normal " << i;
  }
  for (std::size_t i = 0; i < m.triangles.size(); ++i) {
    const glm::uvec3& t = m.triangles[i];
    const glm::dvec3 p(m.positions[t.x]), q(m.positions[t.y]), r(m.positions[t.z]);
    const glm::dvec3 faceNormal = glm::normalize(glm::cross(q - p, r - p));
    const glm::dvec3 vertexNormals = glm::dvec3(m.normals[t.x]) + glm::dvec3(m.normals[t.y]) + glm::dvec3(m.normals[t.z]);
    ASSERT_GT(glm::dot(faceNormal, glm::normalize(vertexNormals)), 0.5) << "triangle " << i;
  }
}

TEST(ProceduralMesh, SphereMatchesTheUnitSphere) {
  for (const int segments : {8, 64, 256}) {
    SCOPED_TRACE(segments);
    const Mesh m = makeSphere(segments);
    EXPECT_NO_THROW(m.validate());
    const int rows = segments / 2;
    EXPECT_EQ(m.positions.size(), static_cast<std::size_t>(segments * (rows - 1) + 2));
    EXPECT_EQ(m.triangles.size(), static_cast<std::size_t>(2 * segments * (rows - 1)));
    expectClosedManifold(m);
    expectUnitOutwardNormals(m);
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      ASSERT_NEAR(glm::length(glm::dvec3(m.positions[i])), 1.0, 1e-6);
      // Exact normals: the analytic surface's, which on a unit sphere is p.
      ASSERT_NEAR(glm::distance(glm::dvec3(m.positions[i]), glm::dvec3(m.normals[i])), 0.0, 1e-6);
    }
    // An inscribed polyhedron falls short of 4π and 4π/3 by O(1/segments²).
    const double h = kTwoPi / segments;
    EXPECT_NEAR(area(m), 4.0 * kPi, 4.0 * kPi * h * h);
    EXPECT_NEAR(volume(m), 4.0 * kPi / 3.0, 4.0 * kPi / 3.0 * 1.5 * h * h);
    EXPECT_LT(area(m), 4.0 * kPi);
    EXPECT_GT(volume(m), 0.0);
  }
  EXPECT_NEAR(area(makeSphere(512)), 4.0 * kPi, 1e-3);
}

TEST(ProceduralMesh, TorusMatchesPappus) {
  const double R = 1.0, r = 0.35;
  const Mesh m = makeTorus(R, r, 256, 128);
  EXPECT_NO_THROW(m.validate());
  expectClosedManifold(m);
  expectUnitOutwardNormals(m);
  // Pappus: area 4π²Rr, volume 2π²Rr².
  EXPECT_NEAR(area(m), 4.0 * kPi * kPi * R * r, 1e-3 * 4.0 * kPi * kPi * R * r);
  EXPECT_NEAR(volume(m), 2.0 * kPi * kPi * R * r * r, 1e-3 * 2.0 * kPi * kPi * R * r * r);
  // Every vertex is on the tube, at distance r from the core circle, with its
  // normal pointing away from the core.
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const glm::dvec3 p(m.positions[i]);
    const glm::dvec3 core = R * glm::normalize(glm::dvec3(p.x, 0.0, p.z));
    ASSERT_NEAR(glm::length(p - core), r, 1e-6);
    ASSERT_NEAR(glm::dot(glm::normalize(p - core), glm::dvec3(m.normals[i])), 1.0, 1e-6);
  }
  // The default torus has the same shape.
  EXPECT_NEAR(volume(makeTorus()), 2.0 * kPi * kPi * R * r * r, 0.02 * 2.0 * kPi * kPi * R * r * r);
}

TEST(ProceduralMesh, BoxIsExact) {
  const Mesh unit = makeBox();
  EXPECT_EQ(unit.positions.size(), 24u);
  EXPECT_EQ(unit.triangles.size(), 12u);
  EXPECT_NEAR(area(unit), 24.0, 1e-9);
  EXPECT_NEAR(volume(unit), 8.0, 1e-9);
  const Mesh m = makeBox(0.5, 1.0, 2.0);
  EXPECT_NO_THROW(m.validate());
  expectUnitOutwardNormals(m);
  EXPECT_NEAR(area(m), 2.0 * (1.0 * 2.0 + 1.0 * 4.0 + 2.0 * 4.0), 1e-9);
  EXPECT_NEAR(volume(m), 1.0 * 2.0 * 4.0, 1e-9);
  // Flat shading: each vertex's normal is its face's, and it lies on that face.
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    const glm::dvec3 n(m.normals[i]);
    EXPECT_NEAR(glm::dot(glm::abs(n), glm::dvec3(1.0)), 1.0, 1e-12);
    EXPECT_NEAR(glm::dot(glm::dvec3(m.positions[i]), n), glm::dot(glm::abs(n), glm::dvec3(0.5, 1.0, 2.0)), 1e-6);
  }
  const Bounds b = m.bounds();
  EXPECT_EQ(b.lo, glm::dvec3(-0.5, -1.0, -2.0));
  EXPECT_EQ(b.hi, glm::dvec3(0.5, 1.0, 2.0));
}

TEST(ProceduralMesh, PlaneFacesUp) {
  for (const int n : {1, 7}) {
    SCOPED_TRACE(n);
    const Mesh m = makePlane(2.5, n);
    EXPECT_NO_THROW(m.validate());
    EXPECT_EQ(m.positions.size(), static_cast<std::size_t>((n + 1) * (n + 1)));
    EXPECT_EQ(m.triangles.size(), static_cast<std::size_t>(2 * n * n));
    expectUnitOutwardNormals(m);
    EXPECT_NEAR(area(m), 25.0, 1e-5);
    for (const glm::uvec3& t : m.triangles) {
      const glm::dvec3 p(m.positions[t.x]), q(m.positions[t.y]), r(m.positions[t.z]);
      EXPECT_GT(glm::cross(q - p, r - p).y, 0.0);
    }
    const Bounds b = m.bounds();
    EXPECT_EQ(b.lo, glm::dvec3(-2.5, 0.0, -2.5));
    EXPECT_EQ(b.hi, glm::dvec3(2.5, 0.0, 2.5));
  }
}

TEST(ProceduralMesh, PillarsAreTheirBoxes) {
  // The slab (2 × 0.1 × 2) and n² pillars of width w = 0.6·(2/n) and the
  // stated heights: area and volume are the boxes' sums.
  for (const auto& [n, k] : {std::pair{4, 1}, std::pair{3, 5}}) {
    SCOPED_TRACE(n);
    const Mesh m = makePillars(n, k);
    EXPECT_NO_THROW(m.validate());
    EXPECT_EQ(m.triangles.size(), static_cast<std::size_t>((1 + n * n) * 6 * 2 * k * k));
    expectUnitOutwardNormals(m);
    const double w = 0.6 * 2.0 / n;
    double a = 2.0 * (4.0 + 0.2 + 0.2), v = 0.4, top = 0.0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double h = 1.2 * (0.4 + 0.6 * ((3 * i + 5 * j) % n) / (n - 1));
        a += 2.0 * w * w + 4.0 * w * h;
        v += w * w * h;
        top = std::max(top, h);
      }
    EXPECT_NEAR(area(m), a, 1e-5);
    EXPECT_NEAR(volume(m), v, 1e-5);
    // Flat shading: every triangle's winding normal is its vertices' normal.
    for (const glm::uvec3& t : m.triangles) {
      const glm::dvec3 p(m.positions[t.x]), q(m.positions[t.y]), r(m.positions[t.z]);
      const glm::dvec3 face = glm::normalize(glm::cross(q - p, r - p));
      for (const std::uint32_t i : {t.x, t.y, t.z}) ASSERT_NEAR(glm::dot(face, glm::dvec3(m.normals[i])), 1.0, 1e-6);
    }
    const Bounds b = m.bounds();
    EXPECT_NEAR(b.lo.y, -0.1, 1e-6);
    EXPECT_NEAR(b.hi.y, top, 1e-6);
    EXPECT_NEAR(b.hi.x, 1.0, 1e-6);
  }
}

TEST(ProceduralMesh, RefusesBadSizes) {
  EXPECT_THROW(makeSphere(3), std::invalid_argument);
  EXPECT_THROW(makeSphere(5000), std::invalid_argument);
  EXPECT_THROW(makeTorus(1.0, 1.0), std::invalid_argument);
  EXPECT_THROW(makeTorus(1.0, -0.1), std::invalid_argument);
  EXPECT_THROW(makeTorus(1.0, 0.3, 2, 8), std::invalid_argument);
  EXPECT_THROW(makeBox(0.0, 1.0, 1.0), std::invalid_argument);
  EXPECT_THROW(makeBox(1.0, std::nan(""), 1.0), std::invalid_argument);
  EXPECT_THROW(makePlane(-1.0), std::invalid_argument);
  EXPECT_THROW(makePlane(1.0, 0), std::invalid_argument);
  EXPECT_THROW(makePillars(1), std::invalid_argument);
  EXPECT_THROW(makePillars(4, 0), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast::assets
