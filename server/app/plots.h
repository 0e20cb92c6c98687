// Figures for the evaluation report, drawn into images (PNG out): grouped
// bar charts and contact sheets. No text is drawn; the report's Markdown
// carries the legend and the numbers beside each figure.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "haarcast/io/image.h"

namespace haarcast::app {

// Distinct colours for up to 8 series (the report lists which is which).
const std::array<std::array<float, 3>, 8>& seriesColours();

// values[group][series] drawn as bars on a log10 axis between the smallest
// and largest positive value (non-positive values are left out), with faint
// gridlines at every decade. Returns the image (linear, values in [0, 1]).
io::RgbImage groupedLogBarChart(const std::vector<std::vector<double>>& values, int width = 640, int height = 320);

// Tiles images (all the same size) into rows × columns with a gap.
io::RgbImage contactSheet(const std::vector<io::RgbImage>& tiles, int columns, int gap = 4);

// The exposure (stops) that puts the log-average luminance of the lit
// pixels at 0.18 (Reinhard's key): what haarcast's PNGs use by default.
double reinhardKeyExposure(const io::RgbImage& image);

}  // namespace haarcast::app
