// libFuzzer target: haarcast::io::parsePly on arbitrary bytes. A refusal is a
// std::runtime_error (mesh_io.h); a mesh it returns must pass Mesh::validate.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string_view>

#include "haarcast/io/mesh_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const haarcast::Mesh mesh =
        haarcast::io::parsePly(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.ply");
    mesh.validate();  // throws std::invalid_argument, which escapes: a finding
  } catch (const std::runtime_error&) {
  }
  return 0;
}
