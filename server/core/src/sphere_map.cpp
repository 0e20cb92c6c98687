#include "haarcast/core/sphere_map.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <glm/geometric.hpp>

namespace haarcast {

void checkLevel(int level, const char* what) {
  if (level < 0 || level > kMaxLevel) {
    throw std::invalid_argument(std::string(what) + ": map level " + std::to_string(level) +
                                " is outside [0, " + std::to_string(kMaxLevel) + "]");
  }
}

Spherical directionToSpherical(const glm::dvec3& d) {
  const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  const double y = std::clamp(d.y / len, -1.0, 1.0);
  double phi = std::atan2(d.x, d.z);  // from +Z toward +X
  if (phi < 0.0) phi += kTwoPi;
  if (phi >= kTwoPi) phi -= kTwoPi;
  return {std::acos(y), phi};
}

double pixelSolidAngle(int level, int row) {
  const int m = mapSize(level);
  const double t0 = row * kPi / m;
  const double t1 = (row + 1) * kPi / m;
  return (std::cos(t0) - std::cos(t1)) * kTwoPi / m;
}

SphereMap::SphereMap(int level, float fill) : level_(level) {
  checkLevel(level, "SphereMap");
  values_.assign(static_cast<std::size_t>(mapSize(level)) * static_cast<std::size_t>(mapSize(level)), fill);
}

SphereMap SphereMap::fromFunction(int level, const std::function<double(const glm::dvec3&)>& f) {
  SphereMap map(level);
  const int m = map.size();
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < m; ++j) {
      map.at(i, j) = static_cast<float>(f(sphericalToDirection(rowTheta(level, i), colPhi(level, j))));
    }
  }
  return map;
}

SphereMap SphereMap::downsampled(int coarser) const {
  checkLevel(coarser, "SphereMap::downsampled");
  if (coarser > level_) {
    throw std::invalid_argument("SphereMap::downsampled: level " + std::to_string(coarser) + " is finer than the map's " +
                                std::to_string(level_));
  }
  const int f = 1 << (level_ - coarser);
  SphereMap out(coarser);
  const int m = out.size();
  for (int i = 0; i < m; ++i) {
    // Rows of one band share their solid angle across the band's columns.
    double bandSolid = 0.0;
    for (int di = 0; di < f; ++di) bandSolid += pixelSolidAngle(level_, i * f + di);
    for (int j = 0; j < m; ++j) {
      double sum = 0.0;
      for (int di = 0; di < f; ++di) {
        double row = 0.0;
        for (int dj = 0; dj < f; ++dj) row += at(i * f + di, j * f + dj);
        sum += row * pixelSolidAngle(level_, i * f + di);
      }
      out.at(i, j) = static_cast<float>(sum / (bandSolid * f));
    }
  }
  return out;
}

double SphereMap::integral() const {
  double sum = 0.0;
  const int m = size();
  for (int i = 0; i < m; ++i) {
    double row = 0.0;
    for (int j = 0; j < m; ++j) row += at(i, j);
    sum += row * pixelSolidAngle(level_, i);
  }
  return sum;
}

BilinearTaps bilinearTaps(int level, double theta, double phi) {
  const int m = mapSize(level);
  // Continuous pixel coordinates: pixel centres sit at integer + 0.5.
  double y = theta / kPi * m - 0.5;
  const double x = phi / kTwoPi * m - 0.5;
  y = std::clamp(y, 0.0, static_cast<double>(m - 1));
  const double fy = std::floor(y);
  const double fx = std::floor(x);
  BilinearTaps t;
  t.tRow = y - fy;
  t.tCol = x - fx;
  t.row[0] = static_cast<int>(fy);
  t.row[1] = std::min(t.row[0] + 1, m - 1);
  const int jw = static_cast<int>(fx);
  t.col[0] = ((jw % m) + m) % m;
  t.col[1] = (t.col[0] + 1) % m;
  return t;
}

double SphereMap::sampleBilinear(double theta, double phi) const {
  const BilinearTaps t = bilinearTaps(level_, theta, phi);
  const double top = (1.0 - t.tCol) * at(t.row[0], t.col[0]) + t.tCol * at(t.row[0], t.col[1]);
  const double bottom = (1.0 - t.tCol) * at(t.row[1], t.col[0]) + t.tCol * at(t.row[1], t.col[1]);
  return (1.0 - t.tRow) * top + t.tRow * bottom;
}

SphereMap SphereMap::weightedBySolidAngle() const {
  SphereMap out = *this;
  const int m = size();
  for (int i = 0; i < m; ++i) {
    const double w = pixelSolidAngle(level_, i);
    for (int j = 0; j < m; ++j) out.at(i, j) = static_cast<float>(at(i, j) * w);
  }
  return out;
}

shared::LatLongTaps latLongTapsToward(int level, const glm::vec3& direction) {
  const float y = std::clamp(direction.y / glm::length(direction), -1.0f, 1.0f);
  float phi = std::atan2(direction.x, direction.z);
  if (phi < 0.0f) phi += shared::kTwoPiF;
  return shared::latLongTaps(static_cast<shared::uint>(level), std::acos(y), phi);
}

float valueAt(const SphereMap& map, const shared::LatLongTaps& t) {
  const float top = (1.0f - t.tCol) * map.at(static_cast<int>(t.row0), static_cast<int>(t.col0)) +
                    t.tCol * map.at(static_cast<int>(t.row0), static_cast<int>(t.col1));
  const float bottom = (1.0f - t.tCol) * map.at(static_cast<int>(t.row1), static_cast<int>(t.col0)) +
                       t.tCol * map.at(static_cast<int>(t.row1), static_cast<int>(t.col1));
  return (1.0f - t.tRow) * top + t.tRow * bottom;
}

}  // namespace haarcast
