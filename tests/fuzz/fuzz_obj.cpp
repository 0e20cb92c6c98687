// libFuzzer target: haarcast::io::parseObj (tinyobjloader underneath) on
// arbitrary text. A refusal is a std::runtime_error (mesh_io.h); a mesh it
// returns must pass Mesh::validate.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "haarcast/io/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const haarcast::Mesh mesh =
        haarcast::io::parseObj(std::string(reinterpret_cast<const char*>(data), size), "fuzz.obj");
    mesh.validate();  // throws std::invalid_argument, which escapes: a finding
  } catch (const std::runtime_error&) {
  }
  return 0;
}
