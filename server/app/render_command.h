// `haarcast render`: the CPU backend on a scene file or on one object given
// by flags; linear EXR and a tonemapped PNG out.
#pragma once

#include <CLI/CLI.hpp>

namespace haarcast::app {

// Adds the subcommand to `app`; the returned function runs it when parsed.
std::function<int()> addRenderCommand(CLI::App& app);

}  // namespace haarcast::app
