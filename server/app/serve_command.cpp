// PLACEHOLDER (step 4 replaces this file): `haarcast serve`.
#include "serve_command.h"

#include <stdexcept>

namespace haarcast::app {

std::function<int()> addServeCommand(CLI::App& app) {
  auto* c = app.add_subcommand("serve", "Serve frames to CLI and browser clients (step 4)");
  return [c]() -> int {
    if (!c->parsed()) return -1;
    throw std::runtime_error("serve is not built yet");
  };
}

}  // namespace haarcast::app
