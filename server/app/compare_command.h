// `haarcast compare`: the error of a render against a reference image (the
// truth of `haarcast reference`), with the measures of DESIGN.md
// "Measurements": PSNR, MSE, relative L2, brightness ratio, and the
// shadowed / lit split when the reference rendered without occlusion is given.
#pragma once

#include <functional>

#include <CLI/CLI.hpp>

namespace haarcast::app {

std::function<int()> addCompareCommand(CLI::App& app);

}  // namespace haarcast::app
