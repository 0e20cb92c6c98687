// fused's sum from a pixel's neighbours (smooth_sum.h).
#include "haarcast/render/smooth_sum.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

namespace haarcast::render {

std::vector<SmoothSumStage> smoothSumStages(int spacing) {
  if (spacing < 1 || (spacing & (spacing - 1)) != 0)
    throw std::invalid_argument("smooth sum: the spacing " + std::to_string(spacing) + " is not a power of two ≥ 1");
  std::vector<SmoothSumStage> stages{{SmoothSumStage::Kind::Grid, spacing}};
  for (int h = spacing / 2; h >= 1; h /= 2) {
    stages.push_back({SmoothSumStage::Kind::Edges, h});
    stages.push_back({SmoothSumStage::Kind::Centres, h});
  }
  return stages;
}

SmoothSumParents smoothSumParents(const SmoothSumStage& stage, int x, int y, int width, int height) {
  SmoothSumParents out;
  const int h = stage.step;
  auto inside = [&](int px, int py) { return px >= 0 && py >= 0 && px < width && py < height; };
  auto at = [&](int px, int py) { return static_cast<std::uint32_t>(py * width + px); };
  if (stage.kind == SmoothSumStage::Kind::Grid) {
    out.count = x % h == 0 && y % h == 0 ? 0 : -2;
    return out;
  }
  const int period = 2 * h;
  const int rx = x % period, ry = y % period;
  if (stage.kind == SmoothSumStage::Kind::Edges) {
    int dx = 0, dy = 0;
    if (rx == h && ry == 0) {
      dx = 1;  // across
    } else if (rx == 0 && ry == h) {
      dy = 1;  // down
    } else {
      out.count = -2;
      return out;
    }
    if (!inside(x - h * dx, y - h * dy) || !inside(x + h * dx, y + h * dy)) {
      out.count = -1;
      return out;
    }
    out.count = 2;
    out.at[0] = at(x - h * dx, y - h * dy);
    out.at[1] = at(x + h * dx, y + h * dy);
    out.outer = inside(x - 3 * h * dx, y - 3 * h * dy) && inside(x + 3 * h * dx, y + 3 * h * dy);
    if (out.outer) {
      out.at[2] = at(x - 3 * h * dx, y - 3 * h * dy);
      out.at[3] = at(x + 3 * h * dx, y + 3 * h * dy);
    }
    return out;
  }
  if (rx != h || ry != h) {
    out.count = -2;
    return out;
  }
  if (!inside(x - h, y) || !inside(x + h, y) || !inside(x, y - h) || !inside(x, y + h)) {
    out.count = -1;
    return out;
  }
  out.count = 4;
  out.at = {at(x - h, y), at(x + h, y), at(x, y - h), at(x, y + h)};
  return out;
}

bool mirrorsWithinLobe(const glm::vec3& pixel, std::span<const glm::vec3> parents, float lobe) {
  const float cosLimit = std::cos(std::min(kSmoothSumLobeShare * lobe, 3.14159265f));
  for (const glm::vec3& p : parents)
    if (!(glm::dot(pixel, p) >= cosLimit)) return false;
  return true;
}

std::array<float, 3> parentsSum(const SmoothSumParents& parents, std::span<const std::array<float, 3>> sums) {
  const std::size_t n = parents.count == 4 ? 4 : 2;
  std::array<float, 3> mean{};
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t c = 0; c < 3; ++c) mean[c] += sums[k][c];
  for (float& m : mean) m /= static_cast<float>(n);
  return mean;
}

float parentsBrightness(const SmoothSumParents& parents, std::span<const std::array<float, 3>> shown) {
  const std::size_t near = parents.count == 4 ? 4 : 2;
  float dimmest = std::max({shown[0][0], shown[0][1], shown[0][2]});
  for (std::size_t k = 1; k < near; ++k) dimmest = std::min(dimmest, std::max({shown[k][0], shown[k][1], shown[k][2]}));
  return dimmest;
}

bool sumsAgree(const SmoothSumParents& parents, std::span<const std::array<float, 3>> sums, float brightness,
               float tolerance) {
  const float epsilon = tolerance * brightness;
  const bool curve = parents.count == 4 || parents.outer;
  const float stepLimit = curve ? 4.0f * epsilon : epsilon;
  const std::size_t near = parents.count == 4 ? 4 : 2;
  for (std::size_t c = 0; c < 3; ++c) {
    float lo = sums[0][c], hi = lo;
    for (std::size_t k = 1; k < near; ++k) {
      lo = std::min(lo, sums[k][c]);
      hi = std::max(hi, sums[k][c]);
    }
    if (!(hi - lo <= stepLimit)) return false;
    if (!curve) continue;
    const float bend = parents.count == 4 ? 0.25f * std::abs(sums[0][c] + sums[1][c] - sums[2][c] - sums[3][c])
                                          : std::abs(sums[2][c] - sums[0][c] - sums[1][c] + sums[3][c]) / 16.0f;
    if (!(bend <= epsilon)) return false;
  }
  return true;
}

}  // namespace haarcast::render
