// libFuzzer target: haarcast::render::loadScene on arbitrary JSON. The file
// sits alone in its directory, so references to meshes, probes and MERL
// files resolve to nothing there (a refusal); built-in meshes, analytic
// materials and the sky build for real. A refusal is a std::runtime_error
// naming the file, or std::invalid_argument for a bad option value (scene.h).
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "fuzz_input_file.h"
#include "haarcast/render/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const haarcast::render::Scene scene = haarcast::render::loadScene(haarcast::fuzz::inputFile("scene.json", data, size));
    if (scene.objects.empty()) __builtin_trap();  // the loader promises at least one object
  } catch (const std::runtime_error&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
