#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace haarcast::app {

// Registers the subcommand; the returned function runs it when it was parsed
// (its exit code) and returns -1 otherwise.
std::function<int()> addBenchFrameCommand(CLI::App& app);

}  // namespace haarcast::app
