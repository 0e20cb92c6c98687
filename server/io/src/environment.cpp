#include "haarcast/io/environment.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <vector>

namespace haarcast::io {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw std::runtime_error(path + ": " + what);
}

void checkLatLong(const RgbImage& image, const char* what) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3) {
    throw std::invalid_argument(std::string(what) + ": malformed image " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + " holding " + std::to_string(image.rgb.size()) +
                                " floats");
  }
}

// One destination cell's taps along an axis: source index and weight, the
// weight being the measure (sin θ dθ or dφ) of the source kernel over the cell.
struct Tap {
  int source;
  double weight;
};
using AxisWeights = std::vector<std::vector<Tap>>;

// Measure of [t0, t1] (normalised coordinate t ∈ [0, 1] along the axis).
double thetaMeasure(double t0, double t1) { return std::cos(kPi * t0) - std::cos(kPi * t1); }
double phiMeasure(double t0, double t1) { return kTwoPi * (t1 - t0); }

// Weights of one axis: `sources` cells of the image onto `dests` cells of the
// map, both tiling [0, 1]. Box kernel (exact overlaps) where the map is no
// finer than the image; tent kernel between source centres otherwise,
// integrated by `sub` sub-intervals per destination cell, each weighted by its
// exact measure so that a destination cell's weights sum to its measure.
template <typename Measure>
AxisWeights axisWeights(int sources, int dests, bool wraps, int sub, Measure measure) {
  AxisWeights weights(static_cast<std::size_t>(dests));
  const long long ns = sources, nd = dests;
  if (dests <= sources) {
    for (long long d = 0; d < nd; ++d) {
      // Source cells [s/ns, (s+1)/ns] meeting [d/nd, (d+1)/nd]: integer bounds, no rounding.
      const long long first = d * ns / nd;
      const long long last = ((d + 1) * ns - 1) / nd;
      const double lo = static_cast<double>(d) / static_cast<double>(nd);
      const double hi = static_cast<double>(d + 1) / static_cast<double>(nd);
      for (long long s = first; s <= last; ++s) {
        const double a = std::max(lo, static_cast<double>(s) / static_cast<double>(ns));
        const double b = std::min(hi, static_cast<double>(s + 1) / static_cast<double>(ns));
        if (b > a) weights[static_cast<std::size_t>(d)].push_back({static_cast<int>(s), measure(a, b)});
      }
    }
    return weights;
  }
  for (int d = 0; d < dests; ++d) {
    std::vector<Tap>& taps = weights[static_cast<std::size_t>(d)];
    const auto add = [&taps](int s, double w) {
      if (w == 0.0) return;
      for (Tap& t : taps) {
        if (t.source == s) {
          t.weight += w;
          return;
        }
      }
      taps.push_back({s, w});
    };
    for (int k = 0; k < sub; ++k) {
      const double t0 = (d + static_cast<double>(k) / sub) / dests;
      const double t1 = (d + static_cast<double>(k + 1) / sub) / dests;
      const double mu = measure(t0, t1);
      // Continuous source coordinate: source centres sit at integer + ½.
      double x = 0.5 * (t0 + t1) * sources - 0.5;
      if (!wraps) x = std::clamp(x, 0.0, static_cast<double>(sources - 1));
      const double fx = std::floor(x);
      const double frac = x - fx;
      int s0 = static_cast<int>(fx);
      int s1 = s0 + 1;
      if (wraps) {
        s0 = ((s0 % sources) + sources) % sources;
        s1 = s1 % sources;
      } else {
        s1 = std::min(s1, sources - 1);
      }
      add(s0, mu * (1.0 - frac));
      add(s1, mu * frac);
    }
  }
  return weights;
}

// Bilinear lookups in an angular map, using only taps whose centres lie in
// the unit disc: real probes are black outside it, and those pixels must not
// bleed into the rim (the directions around +Z).
class AngularSampler {
 public:
  explicit AngularSampler(const RgbImage& img) : img_(img), n_(img.width) {
    inDisc_.resize(static_cast<std::size_t>(n_) * static_cast<std::size_t>(n_));
    for (int y = 0; y < n_; ++y) {
      for (int x = 0; x < n_; ++x) {
        const double u = (x + 0.5) * 2.0 / n_ - 1.0;
        const double v = 1.0 - (y + 0.5) * 2.0 / n_;
        inDisc_[static_cast<std::size_t>(y) * static_cast<std::size_t>(n_) + static_cast<std::size_t>(x)] =
            u * u + v * v <= 1.0;
      }
    }
  }

  // Adds the value at angular-map point (u, v) (v up) to `acc`.
  void add(double u, double v, double* acc) const {
    // Continuous pixel coordinates: pixel centres sit at integer + ½.
    const double x = (u + 1.0) * 0.5 * n_ - 0.5;
    const double y = (1.0 - v) * 0.5 * n_ - 0.5;
    const double fx = std::floor(x), fy = std::floor(y);
    const double tx = x - fx, ty = y - fy;
    const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
    double sum[3] = {0.0, 0.0, 0.0};
    double wsum = 0.0;
    for (int b = 0; b < 2; ++b) {
      for (int a = 0; a < 2; ++a) {
        const int px = x0 + a, py = y0 + b;
        if (px < 0 || py < 0 || px >= n_ || py >= n_ || !valid(py, px)) continue;
        const double w = (a ? tx : 1.0 - tx) * (b ? ty : 1.0 - ty);
        for (int ch = 0; ch < 3; ++ch) sum[ch] += w * img_.at(py, px, ch);
        wsum += w;
      }
    }
    if (wsum > 0.0) {
      for (int ch = 0; ch < 3; ++ch) acc[ch] += sum[ch] / wsum;
      return;
    }
    // Only right at the rim (the single direction +Z): the nearest pixel.
    const int px = std::clamp(static_cast<int>(std::lround(x)), 0, n_ - 1);
    const int py = std::clamp(static_cast<int>(std::lround(y)), 0, n_ - 1);
    for (int ch = 0; ch < 3; ++ch) acc[ch] += img_.at(py, px, ch);
  }

 private:
  bool valid(int y, int x) const {
    return inDisc_[static_cast<std::size_t>(y) * static_cast<std::size_t>(n_) + static_cast<std::size_t>(x)] != 0;
  }
  const RgbImage& img_;
  int n_;
  std::vector<char> inDisc_;
};

}  // namespace

ProbeLayout parseProbeLayout(std::string_view name) {
  if (name == "auto") return ProbeLayout::Auto;
  if (name == "latlong") return ProbeLayout::LatLong;
  if (name == "angular") return ProbeLayout::Angular;
  throw std::invalid_argument("unknown probe layout \"" + std::string(name) +
                              "\" (expected auto, latlong or angular)");
}

const char* probeLayoutName(ProbeLayout layout) {
  switch (layout) {
    case ProbeLayout::Auto: return "auto";
    case ProbeLayout::LatLong: return "latlong";
    case ProbeLayout::Angular: return "angular";
  }
  return "?";
}

glm::dvec3 latLongProbeDirection(double u, double v) {
  const double theta = kPi * v;
  const double s = std::sin(theta);
  return {-s * std::sin(kTwoPi * u), std::cos(theta), s * std::cos(kTwoPi * u)};
}

std::optional<glm::dvec3> angularProbeDirection(double u, double v) {
  const double r = std::sqrt(u * u + v * v);
  if (r > 1.0) return std::nullopt;
  // sin(πr)/r → π as r → 0.
  const double k = r > 1e-12 ? std::sin(kPi * r) / r : kPi;
  return glm::dvec3(u * k, v * k, -std::cos(kPi * r));
}

glm::dvec2 directionToAngularProbe(const glm::dvec3& d) {
  const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  const double r = std::acos(std::clamp(-d.z / len, -1.0, 1.0)) / kPi;
  const double rho = std::sqrt(d.x * d.x + d.y * d.y);
  if (rho <= 1e-15 * len) return r < 0.5 ? glm::dvec2(0.0, 0.0) : glm::dvec2(1.0, 0.0);
  return {d.x / rho * r, d.y / rho * r};
}

RgbImage latLongProbeToHaarcast(const RgbImage& probe) {
  checkLatLong(probe, "latLongProbeToHaarcast");
  RgbImage out = probe;
  const int w = probe.width;
  for (int row = 0; row < probe.height; ++row) {
    for (int col = 0; col < w; ++col) {
      for (int ch = 0; ch < 3; ++ch) out.at(row, col, ch) = probe.at(row, w - 1 - col, ch);
    }
  }
  return out;
}

RgbImage angularProbeToLatLong(const RgbImage& angular, int supersampling) {
  checkLatLong(angular, "angularProbeToLatLong");
  if (angular.width != angular.height) {
    throw std::invalid_argument("angularProbeToLatLong: an angular map is square, not " +
                                std::to_string(angular.width) + "x" + std::to_string(angular.height));
  }
  if (supersampling < 1 || supersampling > 64) {
    throw std::invalid_argument("angularProbeToLatLong: supersampling " + std::to_string(supersampling) +
                                " is outside [1, 64]");
  }
  const int n = angular.width;
  RgbImage out = makeImage(2 * n, n);
  const int s = supersampling;
  const AngularSampler sampler(angular);
  // Sub-sample positions: equal-area strata, uniform in cos θ within a row
  // and uniform in φ within a column; their sines and cosines are tabulated
  // once, leaving one acos and one sqrt per lookup.
  std::vector<double> sinPhi(static_cast<std::size_t>(out.width * s)), cosPhi(sinPhi.size());
  for (std::size_t k = 0; k < sinPhi.size(); ++k) {
    const double phi = kTwoPi * (static_cast<double>(k) + 0.5) / static_cast<double>(sinPhi.size());
    sinPhi[k] = std::sin(phi);
    cosPhi[k] = std::cos(phi);
  }
  std::vector<double> sinTheta(static_cast<std::size_t>(s)), cosTheta(sinTheta.size());
  for (int row = 0; row < out.height; ++row) {
    const double c0 = std::cos(kPi * row / out.height);
    const double c1 = std::cos(kPi * (row + 1) / out.height);
    for (int a = 0; a < s; ++a) {
      const double c = c0 + (c1 - c0) * (a + 0.5) / s;
      cosTheta[static_cast<std::size_t>(a)] = c;
      sinTheta[static_cast<std::size_t>(a)] = std::sqrt(std::max(0.0, 1.0 - c * c));
    }
    for (int col = 0; col < out.width; ++col) {
      double acc[3] = {0.0, 0.0, 0.0};
      for (std::size_t a = 0; a < sinTheta.size(); ++a) {
        for (int b = 0; b < s; ++b) {
          const std::size_t k = static_cast<std::size_t>(col * s + b);
          // d = (sin θ sin φ, cos θ, sin θ cos φ), then the angular-map point
          // at angle π·r from −Z along d's (x, y) heading.
          const double dx = sinTheta[a] * sinPhi[k], dy = cosTheta[a], dz = sinTheta[a] * cosPhi[k];
          const double r = std::acos(std::clamp(-dz, -1.0, 1.0)) / kPi;
          const double rho = std::sqrt(dx * dx + dy * dy);
          const double u = rho > 1e-15 ? dx / rho * r : (r < 0.5 ? 0.0 : 1.0);
          const double v = rho > 1e-15 ? dy / rho * r : 0.0;
          sampler.add(u, v, acc);
        }
      }
      for (int ch = 0; ch < 3; ++ch) out.at(row, col, ch) = static_cast<float>(acc[ch] / (s * s));
    }
  }
  return out;
}

RgbImage loadEnvironment(const std::string& path, ProbeLayout layout) {
  RgbImage image = readImage(path);
  for (std::size_t k = 0; k < image.rgb.size(); ++k) {
    if (!std::isfinite(image.rgb[k])) {
      const std::size_t pixel = k / 3;
      const std::size_t bad = static_cast<std::size_t>(
          std::count_if(image.rgb.begin(), image.rgb.end(), [](float v) { return !std::isfinite(v); }));
      fail(path, std::to_string(bad) + " non-finite pixel values (the first at row " +
                     std::to_string(pixel / static_cast<std::size_t>(image.width)) + ", column " +
                     std::to_string(pixel % static_cast<std::size_t>(image.width)) + ")");
    }
  }
  if (layout == ProbeLayout::Auto) {
    if (image.width == 2 * image.height) {
      layout = ProbeLayout::LatLong;
    } else if (image.width == image.height) {
      layout = ProbeLayout::Angular;
    } else {
      fail(path, "cannot tell the probe layout of a " + std::to_string(image.width) + "x" +
                     std::to_string(image.height) +
                     " image: lat-long probes are twice as wide as high, angular maps square; "
                     "name the layout explicitly");
    }
  }
  if (layout == ProbeLayout::Angular) {
    if (image.width != image.height) {
      fail(path, "an angular map must be square, this image is " + std::to_string(image.width) + "x" +
                     std::to_string(image.height));
    }
    return angularProbeToLatLong(image);
  }
  return latLongProbeToHaarcast(image);
}

std::array<double, 3> latLongIntegral(const RgbImage& latlong) {
  checkLatLong(latlong, "latLongIntegral");
  std::array<double, 3> sum{0.0, 0.0, 0.0};
  for (int row = 0; row < latlong.height; ++row) {
    const double solidAngle = thetaMeasure(static_cast<double>(row) / latlong.height,
                                           static_cast<double>(row + 1) / latlong.height) *
                              kTwoPi / latlong.width;
    std::array<double, 3> rowSum{0.0, 0.0, 0.0};
    for (int col = 0; col < latlong.width; ++col) {
      for (int ch = 0; ch < 3; ++ch) rowSum[static_cast<std::size_t>(ch)] += latlong.at(row, col, ch);
    }
    for (std::size_t ch = 0; ch < 3; ++ch) sum[ch] += rowSum[ch] * solidAngle;
  }
  return sum;
}

std::array<SphereMap, 3> environmentToMaps(const RgbImage& latlong, int level, int supersampling) {
  checkLevel(level, "environmentToMaps");
  checkLatLong(latlong, "environmentToMaps");
  if (supersampling < 1 || supersampling > 64) {
    throw std::invalid_argument("environmentToMaps: supersampling " + std::to_string(supersampling) +
                                " is outside [1, 64]");
  }
  const int m = mapSize(level);
  const AxisWeights wPhi = axisWeights(latlong.width, m, true, supersampling, phiMeasure);
  const AxisWeights wTheta = axisWeights(latlong.height, m, false, supersampling, thetaMeasure);

  // Pass 1, along φ: each image row onto the map's columns (unnormalised sums).
  const std::size_t ms = static_cast<std::size_t>(m);
  std::vector<double> rows(static_cast<std::size_t>(latlong.height) * ms * 3, 0.0);
  for (int a = 0; a < latlong.height; ++a) {
    double* out = &rows[static_cast<std::size_t>(a) * ms * 3];
    for (std::size_t j = 0; j < ms; ++j) {
      double acc[3] = {0.0, 0.0, 0.0};
      for (const Tap& t : wPhi[j]) {
        for (int ch = 0; ch < 3; ++ch) acc[ch] += t.weight * latlong.at(a, t.source, ch);
      }
      for (std::size_t ch = 0; ch < 3; ++ch) out[j * 3 + ch] = acc[ch];
    }
  }
  std::vector<double> phiTotal(ms, 0.0);
  for (std::size_t j = 0; j < ms; ++j) {
    for (const Tap& t : wPhi[j]) phiTotal[j] += t.weight;
  }

  // Pass 2, along θ, and the normalisation by the footprint's measure.
  std::array<SphereMap, 3> maps{SphereMap(level), SphereMap(level), SphereMap(level)};
  for (int i = 0; i < m; ++i) {
    double thetaTotal = 0.0;
    for (const Tap& t : wTheta[static_cast<std::size_t>(i)]) thetaTotal += t.weight;
    for (std::size_t j = 0; j < ms; ++j) {
      double acc[3] = {0.0, 0.0, 0.0};
      for (const Tap& t : wTheta[static_cast<std::size_t>(i)]) {
        const double* r = &rows[(static_cast<std::size_t>(t.source) * ms + j) * 3];
        for (int ch = 0; ch < 3; ++ch) acc[ch] += t.weight * r[ch];
      }
      const double norm = 1.0 / (thetaTotal * phiTotal[j]);
      for (std::size_t ch = 0; ch < 3; ++ch) {
        maps[ch].at(i, static_cast<int>(j)) = static_cast<float>(acc[ch] * norm);
      }
    }
  }
  return maps;
}

std::array<SphereMap, 3> loadEnvironmentMaps(const std::string& path, int level, ProbeLayout layout,
                                             int supersampling) {
  checkLevel(level, "loadEnvironmentMaps");
  return environmentToMaps(loadEnvironment(path, layout), level, supersampling);
}

}  // namespace haarcast::io
