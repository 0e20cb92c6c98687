// libFuzzer target: haarcast::io::readExr on arbitrary bytes. A refusal is a
// std::runtime_error naming the file (image.h); anything else — a crash, a
// sanitizer report, another exception, an allocation past libFuzzer's
// -rss_limit_mb — is a finding.
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "fuzz_input_file.h"
#include "haarcast/io/image.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const haarcast::io::RgbImage image = haarcast::io::readExr(haarcast::fuzz::inputFile("probe.exr", data, size));
    // A loaded image is whole: the pixel vector matches its dimensions.
    if (image.rgb.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3) {
      __builtin_trap();
    }
  } catch (const std::runtime_error&) {
  }
  return 0;
}
