#include "plots.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace haarcast::app {

const std::array<std::array<float, 3>, 8>& seriesColours() {
  // Okabe–Ito: distinguishable with colour-vision deficiencies.
  static const std::array<std::array<float, 3>, 8> colours{{{0.90f, 0.62f, 0.00f},
                                                            {0.34f, 0.71f, 0.91f},
                                                            {0.00f, 0.62f, 0.45f},
                                                            {0.94f, 0.89f, 0.26f},
                                                            {0.00f, 0.45f, 0.70f},
                                                            {0.84f, 0.37f, 0.00f},
                                                            {0.80f, 0.47f, 0.65f},
                                                            {0.40f, 0.40f, 0.40f}}};
  return colours;
}

io::RgbImage groupedLogBarChart(const std::vector<std::vector<double>>& values, int width, int height) {
  io::RgbImage img = io::makeImage(width, height);
  std::fill(img.rgb.begin(), img.rgb.end(), 1.0f);
  double lo = INFINITY, hi = -INFINITY;
  std::size_t series = 0;
  for (const auto& g : values) {
    series = std::max(series, g.size());
    for (double v : g)
      if (v > 0.0 && std::isfinite(v)) lo = std::min(lo, std::log10(v)), hi = std::max(hi, std::log10(v));
  }
  if (!(lo <= hi)) return img;  // nothing positive to draw
  lo = std::floor(lo);
  hi = std::ceil(hi + 1e-9);
  const int margin = 12, plotH = height - 2 * margin;
  auto yOf = [&](double logv) { return margin + static_cast<int>((hi - logv) / (hi - lo) * plotH); };
  auto fill = [&](int x0, int x1, int y0, int y1, const std::array<float, 3>& c) {
    for (int y = std::max(0, y0); y < std::min(height, y1); ++y)
      for (int x = std::max(0, x0); x < std::min(width, x1); ++x)
        for (int k = 0; k < 3; ++k) img.at(y, x, k) = c[static_cast<std::size_t>(k)];
  };
  for (double d = lo; d <= hi + 1e-9; d += 1.0) fill(margin, width - margin, yOf(d), yOf(d) + 1, {0.85f, 0.85f, 0.85f});
  const int groups = static_cast<int>(values.size());
  const int groupW = (width - 2 * margin) / std::max(groups, 1);
  const int barW = std::max(1, (groupW - 8) / std::max<int>(static_cast<int>(series), 1));
  for (int g = 0; g < groups; ++g) {
    for (std::size_t s = 0; s < values[static_cast<std::size_t>(g)].size(); ++s) {
      const double v = values[static_cast<std::size_t>(g)][s];
      if (!(v > 0.0) || !std::isfinite(v)) continue;
      const int x0 = margin + g * groupW + 4 + static_cast<int>(s) * barW;
      fill(x0, x0 + barW - 1, yOf(std::log10(v)), height - margin, seriesColours()[s % 8]);
    }
  }
  fill(margin, width - margin, height - margin, height - margin + 1, {0.0f, 0.0f, 0.0f});
  return img;
}

io::RgbImage contactSheet(const std::vector<io::RgbImage>& tiles, int columns, int gap) {
  if (tiles.empty() || columns < 1) throw std::invalid_argument("contactSheet: nothing to tile");
  const int tw = tiles.front().width, th = tiles.front().height;
  const int rows = (static_cast<int>(tiles.size()) + columns - 1) / columns;
  io::RgbImage sheet = io::makeImage(columns * tw + (columns + 1) * gap, rows * th + (rows + 1) * gap);
  std::fill(sheet.rgb.begin(), sheet.rgb.end(), 1.0f);
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    if (tiles[i].width != tw || tiles[i].height != th) throw std::invalid_argument("contactSheet: tiles differ in size");
    const int ox = gap + static_cast<int>(i % static_cast<std::size_t>(columns)) * (tw + gap);
    const int oy = gap + static_cast<int>(i / static_cast<std::size_t>(columns)) * (th + gap);
    for (int y = 0; y < th; ++y)
      for (int x = 0; x < tw; ++x)
        for (int k = 0; k < 3; ++k) sheet.at(oy + y, ox + x, k) = tiles[i].at(y, x, k);
  }
  return sheet;
}

double reinhardKeyExposure(const io::RgbImage& image) {
  // Over the pixels that carry light: an exactly black background (a render
  // with --background black) would otherwise drag the key down and burn out
  // the object.
  double sumLog = 0.0;
  std::size_t lit = 0;
  for (std::size_t i = 0; i + 2 < image.rgb.size(); i += 3) {
    const double y = 0.2126 * image.rgb[i] + 0.7152 * image.rgb[i + 1] + 0.0722 * image.rgb[i + 2];
    if (!(y > 0.0)) continue;
    sumLog += std::log(1e-4 + y);
    ++lit;
  }
  if (lit == 0) return 0.0;
  return std::log2(0.18 / std::exp(sumLog / static_cast<double>(lit)));
}

}  // namespace haarcast::app
