// libFuzzer target: haarcast::io::parseMerlBrdf. A MERL file has exactly one
// size (kMerlFileBytes), so arbitrary bytes only exercise the size check;
// the input is also spread over a file of the right size — its first 12 bytes
// as the header, the rest repeated over the three channels of doubles — so
// that the dims check, the value checks and the non-finite repair see fuzzed
// data.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>

#include "haarcast/io/merl.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace io = haarcast::io;
  const std::string_view raw(reinterpret_cast<const char*>(data), size);
  try {
    io::parseMerlBrdf(raw, "raw.binary");
  } catch (const std::runtime_error&) {
  }
  if (size <= 12) return 0;
  static std::string file(io::kMerlFileBytes, '\0');
  std::memcpy(file.data(), data, 12);
  // The body repeated by doubling the filled part: log₂ copies, not millions.
  const std::size_t body = size - 12;
  std::memcpy(file.data() + 12, data + 12, std::min(body, file.size() - 12));
  for (std::size_t filled = body; 12 + filled < file.size(); filled *= 2) {
    std::memcpy(file.data() + 12 + filled, file.data() + 12, std::min(filled, file.size() - 12 - filled));
  }
  io::MerlLoadOptions options;
  options.repairNonFinite = size % 2 == 1;  // both paths, one decode per input
  try {
    const auto brdf = io::parseMerlBrdf(file, "spread.binary", options);
    // What loads is finite: every cell reads back as a number.
    const glm::dvec3 v = brdf->cell(0, 0, 0);
    if (!(v.x == v.x && v.y == v.y && v.z == v.z)) __builtin_trap();
  } catch (const std::runtime_error&) {
  }
  return 0;
}
