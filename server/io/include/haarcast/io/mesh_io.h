// Triangle meshes from Wavefront OBJ and Stanford PLY files.
//
// Every loader returns a validated Mesh (Mesh::validate) named after the
// file's stem, with one unit normal per vertex: the file's own when it has
// them for every vertex, else Mesh::computeNormals(). Anything wrong with a
// file — it cannot be read, it is truncated, its format or a property type is
// unknown, an index is out of range, a count is absurd (> kMaxMeshElements) —
// throws std::runtime_error whose message starts with the path and says what
// was wrong. Nothing is repaired silently except what is noted below.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "haarcast/core/mesh.h"

namespace haarcast::io {

// No real model comes near this many vertices or faces (the seed's largest,
// Lucy, has 50k here); a larger count in a header is a corrupt or hostile file,
// and refusing it keeps a bad header from allocating gigabytes.
inline constexpr std::size_t kMaxMeshElements = 50'000'000;

// Dispatches on the extension, case-insensitively: .obj or .ply.
Mesh loadMesh(const std::string& path);

// Wavefront OBJ through tinyobjloader; polygons are triangulated, material
// libraries are not read. OBJ indexes positions and normals separately, so a
// vertex here is a unique (position, normal) pair; if any face corner lacks a
// normal the file's normals are ignored and vertices are the positions.
Mesh loadObj(const std::string& path);
// The same from text in memory; `name` names the mesh and the errors.
Mesh parseObj(const std::string& text, const std::string& name);

// Stanford PLY (Turk 1994; the format as written by the Stanford scanning
// repository, VTK and rply): `format ascii 1.0`, `binary_little_endian 1.0`
// or `binary_big_endian 1.0`. Reads `element vertex` (x, y, z and optionally
// nx, ny, nz, each of any scalar type; other properties skipped) and
// `element face` with a list property named `vertex_indices` or
// `vertex_index` (any integer count and index types); other elements and
// properties, scalar or list, are skipped. Polygons are fan-triangulated.
Mesh loadPly(const std::string& path);
// The same from the file's bytes in memory; `name` names the mesh and the
// errors. A pure function over bytes, so it can be fuzzed.
Mesh parsePly(std::string_view bytes, const std::string& name);

}  // namespace haarcast::io
