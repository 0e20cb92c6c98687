// A triangle mesh in its object frame: pure data, shared by the loaders, the
// built-in meshes, visibility, the G-buffer and the Monte Carlo reference.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace haarcast {

struct Bounds {
  glm::dvec3 lo{0.0}, hi{0.0};
  glm::dvec3 centre() const { return 0.5 * (lo + hi); }
  double radius() const;  // half the diagonal
};

struct Mesh {
  std::string name;
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  // one unit normal per vertex (empty until computed or loaded)
  std::vector<glm::uvec3> triangles;

  // Area-weighted vertex normals from the faces (what the loaders call when a
  // file has none). Degenerate faces contribute nothing; a vertex on none
  // gets +Y.
  void computeNormals();
  // Throws std::invalid_argument naming the problem: no triangles, an index
  // out of range, a non-finite position, normals of the wrong count.
  void validate() const;
  Bounds bounds() const;
};

// The mesh itself when it has normals, else a copy with computeNormals():
// what every consumer of shading normals (renderers, visibility) needs.
std::shared_ptr<const Mesh> withNormals(std::shared_ptr<const Mesh> mesh);

}  // namespace haarcast
