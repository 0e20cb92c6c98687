#include "plots.h"

#include <cmath>
#include <cstddef>

namespace haarcast::app {

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
