// Shadow rays toward the point lights (point_lights.h).
#include "haarcast/render/point_lights.h"

#include <algorithm>
#include <bit>
#include <atomic>
#include <cmath>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>

#include "haarcast/core/check.h"
#include "haarcast/core/parallel.h"
#include "haarcast/core/shared_layout.h"

namespace haarcast::render {

ShadingPoint shadingPoint(const Mesh& mesh, const glm::uvec3& triangle, const float b[3], const glm::mat4& objectToWorld,
                          const glm::mat3& rotation, float shift) {
  const glm::vec3 p = b[0] * mesh.positions[triangle.x] + b[1] * mesh.positions[triangle.y] + b[2] * mesh.positions[triangle.z];
  const glm::vec3 n = b[0] * mesh.normals[triangle.x] + b[1] * mesh.normals[triangle.y] + b[2] * mesh.normals[triangle.z];
  ShadingPoint s;
  s.position = glm::vec3(objectToWorld * glm::vec4(p, 1.0f));
  // A pose scales uniformly, so normals turn with its rotation alone.
  const glm::vec3 world = rotation * n;
  const float len = glm::length(world);
  s.normal = len > 0.0f && std::isfinite(len) ? world / len : glm::vec3(0.0f);
  s.shift = shift;
  return s;
}

std::uint32_t pointLightMask(const RayScene& world, const ShadingPoint& p, std::span<const glm::vec3> directions) {
  HC_CHECK_LE(directions.size(), std::size_t{32});
  std::uint32_t mask = 0;
  for (std::size_t k = 0; k < directions.size(); ++k) {
    if (!(glm::dot(p.normal, directions[k]) > 0.0f)) continue;  // below the shading horizon: ρ·cos is 0
    Ray r;
    r.origin = p.position + p.normal * p.shift;
    r.direction = directions[k];
    if (!world.occluded(r)) mask |= 1u << k;
  }
  return mask;
}

std::uint32_t raysMissingSpheres(const glm::vec3& origin, std::span<const glm::vec3> directions, std::span<const glm::vec4> spheres) {
  HC_CHECK_LE(directions.size(), std::size_t{32});
  std::uint32_t open = directions.size() == 32 ? ~0u : (1u << directions.size()) - 1u;
  // Sphere by sphere, the origin's offset once, then each ray still open.
  for (const glm::vec4& s : spheres) {
    const glm::vec3 toCentre = glm::vec3(s) - origin;
    const float r2 = (s.w * 1.001f) * (s.w * 1.001f);
    const float distance2 = glm::dot(toCentre, toCentre);
    if (distance2 <= r2) return 0u;  // the origin inside: anything may block
    for (std::uint32_t left = open; left != 0u; left &= left - 1u) {
      const int k = std::countr_zero(left);
      const glm::vec3& d = directions[static_cast<std::size_t>(k)];
      const float along = glm::dot(toCentre, d);
      // In front of the origin, and the centre's squared distance to the
      // line, |c − o|² − ((c − o)·d)²/|d|², within the radius.
      if (along > 0.0f && distance2 - along * along / glm::dot(d, d) <= r2) open &= ~(1u << k);
    }
    if (open == 0u) return 0u;
  }
  return open;
}

void pointLightMasks(const RayScene& world, std::span<const ShadingPoint> points, std::span<const glm::vec3> directions,
                     std::span<std::uint32_t> masks, const GroundRays& ground) {
  HC_CHECK_LE(directions.size(), std::size_t{32});
  HC_CHECK_EQ(points.size(), masks.size());
  if (!ground.onGround.empty()) HC_CHECK_EQ(ground.onGround.size(), points.size());
  std::fill(masks.begin(), masks.end(), 0u);
  // Per thread, kept across calls: no allocation per row.
  thread_local std::vector<glm::vec3> origins;
  thread_local std::vector<std::uint32_t> which;
  thread_local std::vector<std::uint8_t> blocked;
  thread_local std::vector<std::uint32_t> untraced;  // per point, the rays that miss every blocker
  untraced.assign(points.size(), 0u);
  for (std::size_t i = 0; i < points.size() && !ground.onGround.empty(); ++i) {
    const ShadingPoint& p = points[i];
    if (ground.onGround[i]) untraced[i] = raysMissingSpheres(p.position + p.normal * p.shift, directions, ground.blockers);
  }
  for (std::size_t k = 0; k < directions.size(); ++k) {
    origins.clear();
    which.clear();
    for (std::size_t i = 0; i < points.size(); ++i) {
      const ShadingPoint& p = points[i];
      if (!(glm::dot(p.normal, directions[k]) > 0.0f)) continue;  // below the shading horizon, as pointLightMask
      if ((untraced[i] >> k) & 1u) {
        masks[i] |= 1u << k;
        continue;
      }
      origins.push_back(p.position + p.normal * p.shift);
      which.push_back(static_cast<std::uint32_t>(i));
    }
    blocked.resize(origins.size());
    world.occludedToward(origins, directions[k], 0.0f, blocked);
    for (std::size_t j = 0; j < origins.size(); ++j)
      if (!blocked[j]) masks[which[j]] |= 1u << k;
  }
}

std::uint32_t lobeRayBit(const RayScene& world, const ShadingPoint& p, const glm::vec3& eye) {
  const glm::vec3 toward = glm::normalize(eye - p.position);
  const glm::vec3 mirror = 2.0f * glm::dot(p.normal, toward) * p.normal - toward;
  if (!(glm::dot(p.normal, mirror) > 0.0f)) return 0u;  // a back-facing normal: no lobe above the horizon
  Ray r;
  r.origin = p.position + p.normal * p.shift;
  r.direction = mirror;
  return world.occluded(r) ? 0u : shared::kLobeSeenBit;
}

namespace {

// One direction of a cone toward an occluder: where it goes, its cosine
// with the sample's normal, and its share of the cone's solid angle with the
// occluder's fade (the weight a blocked direction takes, before the light).
struct ConeRay {
  glm::vec3 direction;
  float cosine;
  float weight;
};

// The cone rays of SkyOccluders from `origin` with normal `normal`, toward
// every occluder but `skip`'s (an object index, or none), each direction
// once, none below the horizon. `maxScale` caps groundSkyScale.
void coneRays(const glm::vec3& origin, const glm::vec3& normal, const SkyOccluders& sky, std::optional<std::uint32_t> skip,
              int maxScale, std::vector<ConeRay>& out) {
  out.clear();
  auto cone = [&](std::size_t k, glm::vec3& axis, float& cosAlpha) {
    const glm::vec3 toward = glm::vec3(sky.occluders[k]) - origin;
    const float radius = sky.occluders[k].w;
    const float distance = glm::length(toward);
    if (!(distance > 0.0f)) return false;
    axis = toward / distance;
    // The cone's half-angle; inside the sphere, the hemisphere about the axis.
    cosAlpha = distance > radius ? std::sqrt(1.0f - (radius / distance) * (radius / distance)) : 0.0f;
    return true;
  };
  auto skipped = [&](std::size_t k) { return skip && sky.objects[k] == *skip; };
  for (std::size_t k = 0; k < sky.occluders.size(); ++k) {
    if (skipped(k)) continue;
    glm::vec3 axis;
    float cosAlpha;
    if (!cone(k, axis, cosAlpha)) continue;
    const float sinAlpha = std::sqrt(std::max(0.0f, 1.0f - cosAlpha * cosAlpha));
    const float solid = static_cast<float>(kTwoPi) * (1.0f - cosAlpha);
    // Its largest cosine with the normal bounds what it can hide.
    const float cosAxis = glm::dot(axis, normal);
    const float sinAxis = std::sqrt(std::max(0.0f, 1.0f - cosAxis * cosAxis));
    const float cosMax = cosAxis >= cosAlpha ? 1.0f : cosAxis * cosAlpha + sinAxis * sinAlpha;
    const float bound = solid * cosMax / static_cast<float>(kPi);
    if (cosMax <= 0.0f || bound < sky.minShare) continue;
    // Faded in over [minShare, 2·minShare] of the bound, so no step marks
    // where the rays begin.
    const float t = std::min(1.0f, bound / static_cast<float>(sky.minShare) - 1.0f);
    const float fade = t * t * (3.0f - 2.0f * t);
    const glm::vec3 helper = std::abs(axis.y) < 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
    const glm::vec3 t1 = glm::normalize(glm::cross(helper, axis));
    const glm::vec3 t2 = glm::cross(axis, t1);
    // More directions in a wider cone (shared_rays.h groundSkyScale).
    const int scale = std::min(static_cast<int>(shared::groundSkyScale(solid)), maxScale);
    const int rings = kGroundSkyRings * scale, sectors = kGroundSkySectors * scale;
    const float share = fade * solid / static_cast<float>(rings * sectors);
    for (int ring = 0; ring < rings; ++ring) {
      // Equal solid angle per ring: cos θ uniform over [cos α, 1].
      const float cosTheta = 1.0f - (static_cast<float>(ring) + 0.5f) / static_cast<float>(rings) * (1.0f - cosAlpha);
      const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
      for (int sector = 0; sector < sectors; ++sector) {
        const float phi = static_cast<float>(kTwoPi) * (static_cast<float>(sector) + 0.5f * static_cast<float>(ring % 2) + 0.25f) /
                          static_cast<float>(sectors);
        const glm::vec3 d = sinTheta * std::cos(phi) * t1 + sinTheta * std::sin(phi) * t2 + cosTheta * axis;
        const float cosine = glm::dot(d, normal);
        if (cosine <= 0.0f) continue;
        // Counted once: a direction inside an earlier occluder's cone was taken there.
        bool earlier = false;
        for (std::size_t j = 0; j < k && !earlier; ++j) {
          glm::vec3 aj;
          float cj;
          earlier = !skipped(j) && cone(j, aj, cj) && glm::dot(d, aj) > cj;
        }
        if (!earlier) out.push_back({d, cosine, share});
      }
    }
  }
}

// Where a world direction falls on the sky's maps (environment frame), in
// float, as the device's ray-generation shader takes it (shadow_rays.rgen
// lightAt): one set of taps for the luminance and the three colours.
// (In double through directionToSpherical and SphereMap::sampleBilinear,
// the lookups of the blocked rays cost a tenth of a 256² frame.)
shared::LatLongTaps skyTaps(const SkyOccluders& sky, const glm::vec3& world) {
  return latLongTapsToward(sky.luminance->level(), sky.toEnvironment * world);
}

}  // namespace

float groundSkyOcclusion(const RayScene& world, const ShadingPoint& p, const SkyOccluders& sky) {
  if (!(sky.total > 0.0) || sky.occluders.empty() || !sky.luminance) return 0.0f;
  const glm::vec3 origin = p.position + p.normal * p.shift;
  // Per thread, kept across samples: no allocation per sample.
  thread_local std::vector<ConeRay> rays;
  thread_local std::vector<glm::vec3> directions;
  thread_local std::vector<std::uint8_t> blocked;
  coneRays(origin, p.normal, sky, std::nullopt, static_cast<int>(shared::kGroundSkyMaxScale), rays);
  if (rays.empty()) return 0.0f;
  directions.resize(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) directions[i] = rays[i].direction;
  blocked.resize(rays.size());
  world.occludedFrom(origin, 0.0f, directions, blocked);
  double hidden = 0.0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (!blocked[i]) continue;
    // Each blocked direction takes its share of Σ luminance·cos·ΔΩ.
    hidden += valueAt(*sky.luminance, skyTaps(sky, rays[i].direction)) * rays[i].cosine * rays[i].weight;
  }
  return static_cast<float>(std::clamp(hidden / sky.total, 0.0, 1.0));
}

SkyHidden objectSkyHidden(const RayScene& world, const ShadingPoint& p, std::size_t object, const SkyOccluders& sky) {
  SkyHidden out;
  if (!sky.objectSky || !sky.luminance || !sky.colour || !(glm::dot(p.normal, p.normal) > 0.0f)) return out;
  const glm::vec3 origin = p.position + p.normal * p.shift;
  thread_local std::vector<ConeRay> rays;
  thread_local std::vector<glm::vec3> directions;
  thread_local std::vector<std::uint8_t> blocked;
  thread_local std::vector<std::uint8_t> own;
  coneRays(origin, p.normal, sky, static_cast<std::uint32_t>(object), static_cast<int>(shared::kObjectSkyMaxScale), rays);
  // Below the ground's plane the ground hides the light already.
  if (sky.ground)
    std::erase_if(rays, [&](const ConeRay& r) { return !(glm::dot(r.direction, sky.normal) > 0.0f); });
  if (rays.empty()) return out;
  directions.resize(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) directions[i] = rays[i].direction;
  blocked.resize(rays.size());
  world.occludedFrom(origin, 0.0f, directions, blocked);
  // Of the blocked ones, those the object itself blocks are its own
  // visibility's: asked of the object alone.
  std::size_t kept = 0;
  for (std::size_t i = 0; i < rays.size(); ++i)
    if (blocked[i]) rays[kept++] = rays[i];
  rays.resize(kept);
  if (rays.empty()) return out;
  directions.resize(rays.size());
  for (std::size_t i = 0; i < rays.size(); ++i) directions[i] = rays[i].direction;
  own.resize(rays.size());
  world.occludedByObjectFrom(object, origin, 0.0f, directions, own);
  glm::vec3 mean(0.0f), sum(0.0f);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    if (own[i]) continue;
    const shared::LatLongTaps t = skyTaps(sky, rays[i].direction);
    const glm::vec3 colour(valueAt((*sky.colour)[0], t), valueAt((*sky.colour)[1], t), valueAt((*sky.colour)[2], t));
    mean += valueAt(*sky.luminance, t) * rays[i].weight * rays[i].direction;
    sum += colour * (rays[i].cosine * rays[i].weight);
  }
  const float length = glm::length(mean);
  if (!(length > 0.0f)) return out;
  out.direction = mean / length;
  out.power = sum;  // Σ L·cos·ΔΩ: the irradiance the hidden directions would give (shared_rays.h HiddenLight)
  return out;
}

shared::HiddenLight hiddenLightOf(const SkyHidden& hidden, const glm::mat3& rotation) {
  shared::HiddenLight out{};
  out.power = hidden.power;
  out.direction = shared::packDirection(glm::transpose(rotation) * hidden.direction);
  return out;
}

std::optional<std::array<float, 3>> hiddenIrradiance(const shared::HiddenLight& hidden) {
  if (!(hidden.power.x > 0.0f || hidden.power.y > 0.0f || hidden.power.z > 0.0f)) return std::nullopt;
  return std::array<float, 3>{hidden.power.x, hidden.power.y, hidden.power.z};
}

bool interiorPixel(std::size_t pixel, std::size_t width, std::size_t height, const std::function<bool(std::size_t)>& ground) {
  const long x = static_cast<long>(pixel % width), y = static_cast<long>(pixel / width);
  for (long dy = -1; dy <= 1; ++dy)
    for (long dx = -1; dx <= 1; ++dx) {
      const long xx = std::clamp(x + dx, 0L, static_cast<long>(width) - 1), yy = std::clamp(y + dy, 0L, static_cast<long>(height) - 1);
      if (!ground(static_cast<std::size_t>(yy) * width + static_cast<std::size_t>(xx))) return false;
    }
  return true;
}

int groundSkyStep(int width, int height) { return std::clamp((std::max(width, height) + 20) / 40, 4, 16); }

GroundSkyGrid::GroundSkyGrid(int width, int height)
    : width_(width),
      height_(height),
      step_(groundSkyStep(width, height)),
      columns_((width - 1) / step_ + 2),
      rows_((height - 1) / step_ + 2),
      fineStep_(static_cast<int>(shared::groundSkyFineStep(static_cast<shared::uint>(step_)))),
      fineColumns_((width - 1) / fineStep_ + 2),
      fineRows_((height - 1) / fineStep_ + 2) {
  HC_CHECK_LT(0, width);
  HC_CHECK_LT(0, height);
  value_.assign(static_cast<std::size_t>(columns_) * static_cast<std::size_t>(rows_), -1.0f);
  fine_.assign(static_cast<std::size_t>(fineColumns_) * static_cast<std::size_t>(fineRows_), -1.0f);
}

namespace {

// Pixel column (row) of grid column (row) i at this spacing, the last one
// clamped to the frame's edge.
int gridPixel(int i, int step, int extent) { return std::min(i * step, extent - 1); }

// The blend of cell (i, j)'s corners in `values` (columns wide) at pixel
// (x, y), or nullopt when a corner is not the ground.
std::optional<float> blendCell(const std::vector<float>& values, int columns, int step, int width, int height, int x, int y) {
  const int i = x / step, j = y / step;
  const int x0 = gridPixel(i, step, width), x1 = gridPixel(i + 1, step, width);
  const int y0 = gridPixel(j, step, height), y1 = gridPixel(j + 1, step, height);
  const float tx = x1 > x0 ? static_cast<float>(x - x0) / static_cast<float>(x1 - x0) : 0.0f;
  const float ty = y1 > y0 ? static_cast<float>(y - y0) / static_cast<float>(y1 - y0) : 0.0f;
  float sum = 0.0f;
  for (int dj = 0; dj < 2; ++dj) {
    for (int di = 0; di < 2; ++di) {
      const float v = values[static_cast<std::size_t>(j + dj) * static_cast<std::size_t>(columns) + static_cast<std::size_t>(i + di)];
      if (v < 0.0f) return std::nullopt;
      sum += (di ? tx : 1.0f - tx) * (dj ? ty : 1.0f - ty) * v;
    }
  }
  return sum;
}

}  // namespace

bool GroundSkyGrid::crossed(int i, int j) const {
  for (int dj = 0; dj < 2; ++dj)
    for (int di = 0; di < 2; ++di)
      if (value_[static_cast<std::size_t>(j + dj) * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(i + di)] < 0.0f)
        return true;
  return false;
}

bool GroundSkyGrid::fineNeeded(int k, int l) const {
  using shared::uint;
  const auto [f, c] = std::pair{static_cast<uint>(fineStep_), static_cast<uint>(step_)};
  const uint i0 = shared::groundFineFirstCell(static_cast<uint>(k), f, c);
  const uint i1 = shared::groundFineLastCell(static_cast<uint>(k), f, c, static_cast<uint>(width_));
  const uint j0 = shared::groundFineFirstCell(static_cast<uint>(l), f, c);
  const uint j1 = shared::groundFineLastCell(static_cast<uint>(l), f, c, static_cast<uint>(height_));
  for (uint j = j0; j <= j1; ++j)
    for (uint i = i0; i <= i1; ++i)
      if (crossed(static_cast<int>(i), static_cast<int>(j))) return true;
  return false;
}

void GroundSkyGrid::compute(const RayScene& world, const SkyOccluders& sky,
                            const std::function<std::optional<ShadingPoint>(std::size_t pixel)>& point,
                            unsigned threads) {
  auto occlusionAt = [&](int x, int y) {
    const std::optional<ShadingPoint> p = point(static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x));
    return p ? groundSkyOcclusion(world, *p, sky) : -1.0f;
  };
  parallelFor(static_cast<std::size_t>(rows_), [&](std::size_t j) {
    for (int i = 0; i < columns_; ++i)
      value_[j * static_cast<std::size_t>(columns_) + static_cast<std::size_t>(i)] =
          occlusionAt(gridPixel(i, step_, width_), gridPixel(static_cast<int>(j), step_, height_));
  }, {}, threads);
  // The fine points the crossed cells read, after every coarse value is known.
  std::atomic<std::size_t> traced{0};
  parallelFor(static_cast<std::size_t>(fineRows_), [&](std::size_t l) {
    for (int k = 0; k < fineColumns_; ++k) {
      float& v = fine_[l * static_cast<std::size_t>(fineColumns_) + static_cast<std::size_t>(k)];
      v = -1.0f;
      if (!fineNeeded(k, static_cast<int>(l))) continue;
      v = occlusionAt(gridPixel(k, fineStep_, width_), gridPixel(static_cast<int>(l), fineStep_, height_));
      traced.fetch_add(1, std::memory_order_relaxed);
    }
  }, {}, threads);
  fineTraced_ = traced.load();
}

std::optional<float> GroundSkyGrid::blended(std::size_t pixel) const {
  const int x = static_cast<int>(pixel % static_cast<std::size_t>(width_));
  const int y = static_cast<int>(pixel / static_cast<std::size_t>(width_));
  HC_CHECK_LT(y, height_);
  if (const std::optional<float> v = blendCell(value_, columns_, step_, width_, height_, x, y)) return v;
  return blendCell(fine_, fineColumns_, fineStep_, width_, height_, x, y);
}

std::uint32_t withGroundOcclusion(std::uint32_t lightBits, float occlusion) {
  HC_CHECK_LT(lightBits, 1u << shared::kGroundOcclusionShift);
  const float share = std::clamp(occlusion, 0.0f, 1.0f);
  return lightBits | (static_cast<std::uint32_t>(std::lround(share * shared::kGroundOcclusionSteps)) << shared::kGroundOcclusionShift);
}

}  // namespace haarcast::render
