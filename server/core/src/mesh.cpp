#include "haarcast/core/mesh.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

namespace haarcast {

double Bounds::radius() const { return 0.5 * glm::length(hi - lo); }

void Mesh::computeNormals() {
  std::vector<glm::dvec3> sum(positions.size(), glm::dvec3(0.0));
  for (const glm::uvec3& t : triangles) {
    const glm::dvec3 a(positions[t.x]), b(positions[t.y]), c(positions[t.z]);
    const glm::dvec3 n = glm::cross(b - a, c - a);  // length = 2·area: area weighting for free
    sum[t.x] += n;
    sum[t.y] += n;
    sum[t.z] += n;
  }
  normals.resize(positions.size());
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const double len = glm::length(sum[i]);
    normals[i] = len > 0.0 ? glm::vec3(sum[i] / len) : glm::vec3(0.0f, 1.0f, 0.0f);
  }
}

void Mesh::validate() const {
  const std::string who = "mesh \"" + name + "\": ";
  if (triangles.empty()) throw std::invalid_argument(who + "has no triangles");
  for (std::size_t i = 0; i < positions.size(); ++i) {
    const glm::vec3& p = positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      throw std::invalid_argument(who + "vertex " + std::to_string(i) + " has a non-finite position");
    }
  }
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    const glm::uvec3& t = triangles[i];
    if (t.x >= positions.size() || t.y >= positions.size() || t.z >= positions.size()) {
      throw std::invalid_argument(who + "triangle " + std::to_string(i) + " refers to a vertex past the " +
                                  std::to_string(positions.size()) + " it has");
    }
  }
  if (!normals.empty() && normals.size() != positions.size()) {
    throw std::invalid_argument(who + std::to_string(normals.size()) + " normals for " +
                                std::to_string(positions.size()) + " vertices");
  }
}

std::shared_ptr<const Mesh> withNormals(std::shared_ptr<const Mesh> mesh) {
  if (!mesh->normals.empty()) return mesh;
  auto copy = std::make_shared<Mesh>(*mesh);
  copy->computeNormals();
  return copy;
}

Bounds Mesh::bounds() const {
  Bounds b;
  if (positions.empty()) return b;
  b.lo = b.hi = glm::dvec3(positions.front());
  for (const glm::vec3& p : positions) {
    b.lo = glm::min(b.lo, glm::dvec3(p));
    b.hi = glm::max(b.hi, glm::dvec3(p));
  }
  return b;
}

}  // namespace haarcast
