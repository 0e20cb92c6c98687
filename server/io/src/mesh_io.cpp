// OBJ (through tinyobjloader) mesh loading, what every mesh loader shares
// (mesh_finish.h) and the dispatch on extensions; the PLY reader is ply.cpp.
#include "haarcast/io/mesh_io.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <vector>

#include <glm/geometric.hpp>
#include <tiny_obj_loader.h>

#include "mesh_finish.h"
#include "haarcast/io/input_file.h"

namespace haarcast::io {

[[noreturn]] void detail::meshFail(const std::string& where, const std::string& what) {
  throw std::runtime_error(where + ": " + what);
}

namespace {

using detail::finishMesh;

[[noreturn]] void fail(const std::string& where, const std::string& what) { detail::meshFail(where, what); }

std::string readWholeFile(const std::string& path) {
  if (auto why = whyNotRegularFile(path)) fail(path, "cannot open: " + *why);
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(path, std::string("cannot open: ") + std::strerror(errno));
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) fail(path, "cannot read its size");
  in.seekg(0, std::ios::beg);
  std::string bytes(static_cast<std::size_t>(size), '\0');
  if (!in.read(bytes.data(), size)) fail(path, "read failed");
  return bytes;
}

std::string stemOf(const std::string& path) { return std::filesystem::path(path).stem().string(); }

// Scans do not agree on winding (../shared/data's bunny.ply is wound inward,
// its .obj outward), and normals computed from faces follow the winding. For
// a closed mesh the signed volume Σ a·(b×c)/6 is negative exactly when it is
// wound inward; flip it then. An open or flat mesh encloses no volume worth
// the name, so the flip needs |V| to be a real fraction of the bounds.
void orientOutward(Mesh& mesh) {
  double volume = 0.0;
  for (const glm::uvec3& t : mesh.triangles) {
    volume += glm::dot(glm::dvec3(mesh.positions[t.x]),
                       glm::cross(glm::dvec3(mesh.positions[t.y]), glm::dvec3(mesh.positions[t.z])));
  }
  volume /= 6.0;
  const double r = mesh.bounds().radius();
  if (volume < -1e-3 * r * r * r) {
    for (glm::uvec3& t : mesh.triangles) std::swap(t.y, t.z);
  }
}

}  // namespace

// The tail every loader shares: check what the file gave (indices, finite
// positions), then make the normals unit. A file normal that is zero or not
// finite is replaced by the area-weighted face normal at that vertex rather
// than rejecting a whole scan for one bad vertex; every other defect throws.
Mesh detail::finishMesh(Mesh mesh, const std::string& where) {
  try {
    mesh.validate();
  } catch (const std::invalid_argument& e) {
    fail(where, e.what());
  }
  if (mesh.normals.empty()) {
    orientOutward(mesh);
    mesh.computeNormals();
    return mesh;
  }
  std::vector<std::size_t> bad;
  for (std::size_t i = 0; i < mesh.normals.size(); ++i) {
    const glm::dvec3 n(mesh.normals[i]);
    const double len = glm::length(n);
    if (std::isfinite(len) && len > 1e-30) {
      mesh.normals[i] = glm::vec3(n / len);
    } else {
      bad.push_back(i);
    }
  }
  if (!bad.empty()) {
    Mesh faces = mesh;
    faces.computeNormals();
    for (const std::size_t i : bad) mesh.normals[i] = faces.normals[i];
  }
  return mesh;
}

namespace {

// ---------------------------------------------------------------- OBJ

Mesh objFromReader(const tinyobj::ObjReader& reader, const std::string& where, const std::string& name) {
  // tinyobjloader skips some faces it cannot use and only warns (a quad with
  // an index past the end is dropped); a loader that hides holes in a model
  // is worse than one that refuses it.
  if (reader.Warning().find("out of bounds") != std::string::npos ||
      reader.Warning().find("invalid vertex index") != std::string::npos) {
    std::string warning = reader.Warning();
    warning.erase(std::remove(warning.begin(), warning.end(), '\n'), warning.end());
    fail(where, "index out of range (" + warning + ")");
  }
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  const std::size_t positionCount = attrib.vertices.size() / 3;
  const std::size_t normalCount = attrib.normals.size() / 3;
  if (positionCount > kMaxMeshElements) fail(where, std::to_string(positionCount) + " vertices is absurd");

  std::size_t cornerCount = 0;
  bool everyCornerHasNormal = normalCount > 0;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    for (const unsigned char n : shape.mesh.num_face_vertices) {
      if (n != 3) fail(where, "a face of " + std::to_string(n) + " corners survived triangulation");
    }
    cornerCount += shape.mesh.indices.size();
    for (const tinyobj::index_t& idx : shape.mesh.indices) {
      if (idx.vertex_index < 0 || static_cast<std::size_t>(idx.vertex_index) >= positionCount) {
        fail(where, "vertex index " + std::to_string(idx.vertex_index + 1) + " is outside [1, " +
                        std::to_string(positionCount) + "]");
      }
      if (idx.normal_index < 0) {
        everyCornerHasNormal = false;
      } else if (static_cast<std::size_t>(idx.normal_index) >= normalCount) {
        fail(where, "normal index " + std::to_string(idx.normal_index + 1) + " is outside [1, " +
                        std::to_string(normalCount) + "]");
      }
    }
  }
  if (cornerCount / 3 > kMaxMeshElements) fail(where, std::to_string(cornerCount / 3) + " triangles is absurd");

  Mesh mesh;
  mesh.name = name;
  mesh.triangles.reserve(cornerCount / 3);
  const auto position = [&](int i) {
    const std::size_t k = 3 * static_cast<std::size_t>(i);
    return glm::vec3(attrib.vertices[k], attrib.vertices[k + 1], attrib.vertices[k + 2]);
  };
  if (!everyCornerHasNormal) {
    // Positions only: the file's vertex numbering is kept, so vertex i here is
    // `v` line i + 1 there.
    mesh.positions.reserve(positionCount);
    for (std::size_t i = 0; i < positionCount; ++i) mesh.positions.push_back(position(static_cast<int>(i)));
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
      const auto& indices = shape.mesh.indices;
      for (std::size_t k = 0; k + 2 < indices.size(); k += 3) {
        mesh.triangles.emplace_back(indices[k].vertex_index, indices[k + 1].vertex_index,
                                    indices[k + 2].vertex_index);
      }
    }
    return mesh;
  }

  // A vertex is a unique (position, normal) pair, numbered in order of first
  // use: where a crease gives one position two normals it becomes two vertices.
  std::unordered_map<std::uint64_t, std::uint32_t> vertexOf;
  vertexOf.reserve(positionCount * 2);
  const auto vertex = [&](const tinyobj::index_t& idx) -> std::uint32_t {
    const std::uint64_t key = (static_cast<std::uint64_t>(static_cast<std::uint32_t>(idx.vertex_index)) << 32) |
                              static_cast<std::uint32_t>(idx.normal_index);
    const auto [it, inserted] = vertexOf.try_emplace(key, static_cast<std::uint32_t>(mesh.positions.size()));
    if (inserted) {
      const std::size_t n = 3 * static_cast<std::size_t>(idx.normal_index);
      mesh.positions.push_back(position(idx.vertex_index));
      mesh.normals.emplace_back(attrib.normals[n], attrib.normals[n + 1], attrib.normals[n + 2]);
    }
    return it->second;
  };
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const auto& indices = shape.mesh.indices;
    for (std::size_t k = 0; k + 2 < indices.size(); k += 3) {
      const std::uint32_t a = vertex(indices[k]);
      const std::uint32_t b = vertex(indices[k + 1]);
      const std::uint32_t c = vertex(indices[k + 2]);
      mesh.triangles.emplace_back(a, b, c);
    }
  }
  return mesh;
}

tinyobj::ObjReaderConfig objConfig() {
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  return config;
}

Mesh parseObjAs(const std::string& text, const std::string& where, const std::string& name) {
  tinyobj::ObjReader reader;
  // No material text: haarcast's materials come from its own BRDFs, and an
  // OBJ's mtllib must not make a load touch other files.
  if (!reader.ParseFromString(text, std::string(), objConfig())) {
    std::string error = reader.Error();
    error.erase(std::remove(error.begin(), error.end(), '\n'), error.end());
    fail(where, "not a valid OBJ file: " + error);
  }
  return finishMesh(objFromReader(reader, where, name), where);
}

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

Mesh loadMesh(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".obj") return loadObj(path);
  if (ext == ".ply") return loadPly(path);
  fail(path, "unknown mesh format \"" + ext + "\" (expected .obj or .ply)");
}

Mesh loadObj(const std::string& path) { return parseObjAs(readWholeFile(path), path, stemOf(path)); }

Mesh parseObj(const std::string& text, const std::string& name) { return parseObjAs(text, name, name); }

Mesh loadPly(const std::string& path) { return detail::parsePlyAs(readWholeFile(path), path, stemOf(path)); }

}  // namespace haarcast::io
