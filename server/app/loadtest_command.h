#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace haarcast::app {

// `haarcast loadtest` (docs/loadtest.md): registers the subcommand; the
// returned function runs it when it was parsed (its exit code) and returns
// -1 otherwise.
std::function<int()> addLoadtestCommand(CLI::App& app);

}  // namespace haarcast::app
