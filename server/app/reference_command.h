// `haarcast reference`: the Monte Carlo truth for a render (same flags).
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace haarcast::app {

std::function<int()> addReferenceCommand(CLI::App& app);

}  // namespace haarcast::app
