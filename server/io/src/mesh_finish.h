// What the OBJ (mesh_io.cpp) and PLY (ply.cpp) loaders share: the error
// convention (the file, then what was wrong) and the checks every loaded mesh
// passes before it is returned (mesh_io.h).
#pragma once

#include <string>
#include <string_view>

#include "haarcast/core/mesh.h"

namespace haarcast::io::detail {

// Throws std::runtime_error("<where>: <what>").
[[noreturn]] void meshFail(const std::string& where, const std::string& what);

// Validates the mesh (indices, finite positions) and makes its normals unit,
// computing them from the faces where the file gave none.
Mesh finishMesh(Mesh mesh, const std::string& where);

// The PLY reader: `where` names the file in errors, `name` names the mesh.
Mesh parsePlyAs(std::string_view bytes, const std::string& where, const std::string& name);

}  // namespace haarcast::io::detail
