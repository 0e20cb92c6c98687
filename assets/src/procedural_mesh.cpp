// The built-in meshes. Every triangle is wound so that cross(b − a, c − a)
// is the outward normal: for a surface p(s, t) that is the order
// (p, p + ∂s, p + ∂s + ∂t) whenever ∂s × ∂t points out.
#include "haarcast/assets/procedural_mesh.h"

#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

#include <glm/vec3.hpp>

#include "haarcast/core/sphere_map.h"

namespace haarcast::assets {
namespace {

constexpr int kMaxSegments = 4096;

void checkCount(int n, int lo, const char* what) {
  if (n < lo || n > kMaxSegments) {
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(n) + " is outside [" + std::to_string(lo) +
                                ", " + std::to_string(kMaxSegments) + "]");
  }
}

void checkPositive(double v, const char* what) {
  if (!(v > 0.0) || !std::isfinite(v)) {
    throw std::invalid_argument(std::string(what) + ": " + std::to_string(v) + " is not a positive finite size");
  }
}

glm::uvec3 tri(std::size_t a, std::size_t b, std::size_t c) {
  return {static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b), static_cast<std::uint32_t>(c)};
}

// The box centre ± h appended to `mesh`: six faces, each its own n × n grid of
// quads with the face's normal (makeBox's faces and winding, subdivided).
void appendBox(Mesh& mesh, const glm::dvec3& centre, const glm::dvec3& h, int n) {
  struct Face {
    glm::dvec3 n, t1, t2;  // t1 × t2 = n: corners in t1-then-t2 order run counter-clockwise
  };
  const glm::dvec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  const Face faces[6] = {{x, y, z}, {-x, z, y}, {y, z, x}, {-y, x, z}, {z, x, y}, {-z, y, x}};
  for (const Face& f : faces) {
    const std::size_t first = mesh.positions.size();
    const glm::dvec3 c = centre + f.n * h, a = f.t1 * h, b = f.t2 * h;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        mesh.positions.emplace_back(c + (-1.0 + 2.0 * i / n) * a + (-1.0 + 2.0 * j / n) * b);
        mesh.normals.emplace_back(f.n);
      }
    const auto v = [&](int i, int j) { return first + static_cast<std::size_t>(j) * static_cast<std::size_t>(n + 1) + static_cast<std::size_t>(i); };
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        mesh.triangles.push_back(tri(v(i, j), v(i + 1, j), v(i + 1, j + 1)));
        mesh.triangles.push_back(tri(v(i, j), v(i + 1, j + 1), v(i, j + 1)));
      }
  }
}

}  // namespace

Mesh makeSphere(int segments) {
  checkCount(segments, 4, "makeSphere segments");
  const int rows = segments / 2;  // bands of elevation, pole to pole
  Mesh mesh;
  mesh.name = "sphere";
  // Vertex 0 is the north pole (+Y), then rings r = 1 … rows−1 at θ = rπ/rows,
  // each of `segments` vertices at φ = 2πj/segments, then the south pole.
  mesh.positions.emplace_back(0.0f, 1.0f, 0.0f);
  for (int r = 1; r < rows; ++r) {
    for (int j = 0; j < segments; ++j) {
      mesh.positions.emplace_back(sphericalToDirection(kPi * r / rows, kTwoPi * j / segments));
    }
  }
  mesh.positions.emplace_back(0.0f, -1.0f, 0.0f);
  // On a unit sphere at the origin the exact normal is the position.
  mesh.normals = mesh.positions;

  const auto ring = [&](int r, int j) {
    return 1 + static_cast<std::size_t>(r - 1) * static_cast<std::size_t>(segments) +
           static_cast<std::size_t>((j % segments + segments) % segments);
  };
  const std::size_t south = mesh.positions.size() - 1;
  // Going down in θ then along φ is outward (∂θ × ∂φ = p̂).
  for (int j = 0; j < segments; ++j) mesh.triangles.push_back(tri(0, ring(1, j), ring(1, j + 1)));
  for (int r = 1; r + 1 < rows; ++r) {
    for (int j = 0; j < segments; ++j) {
      mesh.triangles.push_back(tri(ring(r, j), ring(r + 1, j), ring(r + 1, j + 1)));
      mesh.triangles.push_back(tri(ring(r, j), ring(r + 1, j + 1), ring(r, j + 1)));
    }
  }
  for (int j = 0; j < segments; ++j) mesh.triangles.push_back(tri(ring(rows - 1, j), south, ring(rows - 1, j + 1)));
  return mesh;
}

Mesh makeTorus(double majorRadius, double minorRadius, int majorSegments, int minorSegments) {
  checkPositive(majorRadius, "makeTorus majorRadius");
  checkPositive(minorRadius, "makeTorus minorRadius");
  if (!(minorRadius < majorRadius)) {
    throw std::invalid_argument("makeTorus: minorRadius " + std::to_string(minorRadius) +
                                " must be less than majorRadius " + std::to_string(majorRadius) +
                                " (a self-intersecting torus has no well-defined inside)");
  }
  checkCount(majorSegments, 3, "makeTorus majorSegments");
  checkCount(minorSegments, 3, "makeTorus minorSegments");
  Mesh mesh;
  mesh.name = "torus";
  // u runs around +Y (the azimuth φ of the tube's centre), v around the tube
  // from the outer equator towards +Y. Normal n = cos v·ê_r(u) + sin v·ŷ and
  // ∂u × ∂v points along n.
  for (int i = 0; i < majorSegments; ++i) {
    const double u = kTwoPi * i / majorSegments;
    const glm::dvec3 radial(std::sin(u), 0.0, std::cos(u));
    for (int j = 0; j < minorSegments; ++j) {
      const double v = kTwoPi * j / minorSegments;
      const glm::dvec3 n = std::cos(v) * radial + glm::dvec3(0.0, std::sin(v), 0.0);
      mesh.positions.emplace_back(majorRadius * radial + minorRadius * n);
      mesh.normals.emplace_back(n);
    }
  }
  const auto vertex = [&](int i, int j) {
    return static_cast<std::size_t>(i % majorSegments) * static_cast<std::size_t>(minorSegments) +
           static_cast<std::size_t>(j % minorSegments);
  };
  for (int i = 0; i < majorSegments; ++i) {
    for (int j = 0; j < minorSegments; ++j) {
      mesh.triangles.push_back(tri(vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)));
      mesh.triangles.push_back(tri(vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)));
    }
  }
  return mesh;
}

Mesh makeBox(double halfExtentX, double halfExtentY, double halfExtentZ) {
  checkPositive(halfExtentX, "makeBox halfExtentX");
  checkPositive(halfExtentY, "makeBox halfExtentY");
  checkPositive(halfExtentZ, "makeBox halfExtentZ");
  const glm::dvec3 h(halfExtentX, halfExtentY, halfExtentZ);
  struct Face {
    glm::dvec3 n, t1, t2;  // t1 × t2 = n, so corners in t1-then-t2 order run counter-clockwise
  };
  const glm::dvec3 x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  const Face faces[6] = {{x, y, z}, {-x, z, y}, {y, z, x}, {-y, x, z}, {z, x, y}, {-z, y, x}};
  Mesh mesh;
  mesh.name = "box";
  for (const Face& f : faces) {
    const std::size_t first = mesh.positions.size();
    const glm::dvec3 centre = f.n * h;
    const glm::dvec3 a = f.t1 * h, b = f.t2 * h;
    for (const auto& [s1, s2] : {std::pair{-1.0, -1.0}, std::pair{1.0, -1.0}, std::pair{1.0, 1.0}, std::pair{-1.0, 1.0}}) {
      mesh.positions.emplace_back(centre + s1 * a + s2 * b);
      mesh.normals.emplace_back(f.n);
    }
    mesh.triangles.push_back(tri(first, first + 1, first + 2));
    mesh.triangles.push_back(tri(first, first + 2, first + 3));
  }
  return mesh;
}

Mesh makePillars(int pillars, int faceSubdivisions) {
  if (pillars < 2 || pillars > 64) throw std::invalid_argument("makePillars pillars: " + std::to_string(pillars) + " is outside [2, 64]");
  if (faceSubdivisions < 1 || faceSubdivisions > 256) {
    throw std::invalid_argument("makePillars faceSubdivisions: " + std::to_string(faceSubdivisions) + " is outside [1, 256]");
  }
  Mesh mesh;
  mesh.name = "pillars";
  appendBox(mesh, {0.0, -0.05, 0.0}, {1.0, 0.05, 1.0}, faceSubdivisions);
  const int n = pillars;
  const double cell = 2.0 / n, half = 0.3 * cell;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double height = 1.2 * (0.4 + 0.6 * ((3 * i + 5 * j) % n) / (n - 1));
      appendBox(mesh, {-1.0 + (i + 0.5) * cell, 0.5 * height, -1.0 + (j + 0.5) * cell}, {half, 0.5 * height, half},
                faceSubdivisions);
    }
  return mesh;
}

Mesh makePlane(double halfSize, int subdivisions) {
  checkPositive(halfSize, "makePlane halfSize");
  checkCount(subdivisions, 1, "makePlane subdivisions");
  const int n = subdivisions;
  Mesh mesh;
  mesh.name = "plane";
  // Vertex (i, k): x from i, z from k. ∂z × ∂x = +Y, so step in z first.
  for (int i = 0; i <= n; ++i) {
    for (int k = 0; k <= n; ++k) {
      mesh.positions.emplace_back(-halfSize + 2.0 * halfSize * i / n, 0.0, -halfSize + 2.0 * halfSize * k / n);
      mesh.normals.emplace_back(0.0f, 1.0f, 0.0f);
    }
  }
  const auto vertex = [&](int i, int k) {
    return static_cast<std::size_t>(i) * static_cast<std::size_t>(n + 1) + static_cast<std::size_t>(k);
  };
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < n; ++k) {
      mesh.triangles.push_back(tri(vertex(i, k), vertex(i, k + 1), vertex(i + 1, k + 1)));
      mesh.triangles.push_back(tri(vertex(i, k), vertex(i + 1, k + 1), vertex(i + 1, k)));
    }
  }
  return mesh;
}

}  // namespace haarcast::assets
