// PLACEHOLDER (step 3 replaces this file): `haarcast bench-frame`.
#include "bench_frame_command.h"

#include <stdexcept>

namespace haarcast::app {

std::function<int()> addBenchFrameCommand(CLI::App& app) {
  auto* c = app.add_subcommand("bench-frame", "Per-pass frame times of each backend (step 3)");
  return [c]() -> int {
    if (!c->parsed()) return -1;
    throw std::runtime_error("bench-frame is not built yet");
  };
}

}  // namespace haarcast::app
