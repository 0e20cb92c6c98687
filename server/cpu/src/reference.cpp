// The Monte Carlo reference renderer (see reference.h for what it computes,
// how it samples and when it stops).
#include "haarcast/cpu/reference.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/trigonometric.hpp>

#include "haarcast/core/sphere_map.h"
#include "haarcast/core/parallel.h"
#include "haarcast/render/embree_scene.h"
#include "haarcast/render/shading.h"
#include "reference_sampling.h"

namespace haarcast::render {
namespace {

using Clock = std::chrono::steady_clock;

// Probability of the cosine part of the brdf strategy ("defensive" mixture).
constexpr double kDefensiveCosine = 0.1;
// Floor of the environment table, relative to its mean: keeps the density
// positive where the table saw nothing (a feature between its samples, or
// black), so that environment sampling alone stays unbiased.
constexpr double kEnvironmentFloor = 1e-3;
// The largest double below 1: stratified uniforms are clamped to [0, 1).
constexpr double kBelowOne = 1.0 - 0x1p-53;
// Scene occlusion's floor on the shadow-ray offset, relative to the hit
// point's largest coordinate: 64 float ulps (reference.h).
constexpr double kFloatGuard = 0x1p-17;

using namespace reference_sampling;  // PCG32, SphereDistribution, cellMaxima (reference_sampling.h)

// ---- Scene preparation ------------------------------------------------------

struct Strategies {
  bool environment = false, brdf = false, cosine = false;
};

Strategies strategiesOf(ReferenceSampling s) {
  switch (s) {
    case ReferenceSampling::Mis: return {true, true, false};
    case ReferenceSampling::MisCosine: return {true, false, true};
    case ReferenceSampling::Environment: return {true, false, false};
    case ReferenceSampling::Brdf: return {false, true, false};
    case ReferenceSampling::Cosine: return {false, false, true};
  }
  throw std::invalid_argument("reference options: unknown sampling strategy");
}

struct PreparedObject {
  std::shared_ptr<const Mesh> mesh;       // with normals
  const Brdf* brdf = nullptr;
  glm::dmat3 rotation{1.0};               // object → world
  glm::dmat4 objectToWorld{1.0};
  std::unique_ptr<RayScene> self;         // this object alone, object frame (self occlusion only)
  double shift = 0.0;                     // shadow-ray origin offset: object units (self), world units (scene)
  std::vector<SphereDistribution> brdfTables;  // per tabulated θₒ (brdf strategy)
};

// The brdf strategy's tables, one per view elevation θₒ_k = (k + ½)(π/2)/K
// (view at φ = 0), each over the half vector h in the local upper hemisphere.
// Why h: a glossy lobe sits at h ≈ n whatever θₒ, so neighbouring tables
// agree and mixing the two around a pixel's θₒ loses little; in ωᵢ the lobe
// moves by 2Δθₒ between tables, as much as a Phong-64 lobe is wide. The
// density of ωᵢ = 2(ωₒ·h)h − ωₒ is p(h)/(4 ωₒ·h) (Walter et al. 2007,
// eq. 14), so the table holds cell maxima of mean(ρ)·cos θᵢ·4(ωₒ·h), ρ's
// channel mean: proportional to the integrand under a constant light.
std::vector<SphereDistribution> buildBrdfTables(const Brdf& brdf, const ReferenceOptions& o, unsigned threads) {
  const int k = o.brdfTableThetaOut, cols = o.brdfTableWidth, rows = cols / 4;
  std::vector<std::vector<double>> values(static_cast<std::size_t>(k));
  parallelFor(static_cast<std::size_t>(k), threads, [&](std::size_t bin) {
    const double thetaOut = (static_cast<double>(bin) + 0.5) * (kPi / 2.0) / k;
    const glm::dvec3 wo(0.0, std::cos(thetaOut), std::sin(thetaOut));
    std::vector<double>& v = values[bin];
    auto density = [&](const glm::dvec3& h) {
      const double woh = glm::dot(wo, h);
      if (!(woh > 0.0)) return 0.0;
      const glm::dvec3 wi = 2.0 * woh * h - wo;
      return wi.y > 0.0 ? channelMean(brdf.evaluate(wi, wo)) * wi.y * 4.0 * woh : 0.0;
    };
    v = cellMaxima(rows, cols, kPi / 2.0, density, 1);
    double sum = 0.0;
    for (double x : v) sum += x;
    if (!(sum > 0.0) || !std::isfinite(sum)) {
      // ρ is zero (or unusable) for this view: any density will do; take cos θ.
      const std::vector<double> e = SphereDistribution::edges(rows, kPi / 2.0);
      for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
          v[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c)] =
              0.5 * (e[static_cast<std::size_t>(r)] + e[static_cast<std::size_t>(r) + 1]);
    }
  });
  std::vector<SphereDistribution> tables;
  tables.reserve(values.size());
  for (auto& v : values) tables.emplace_back(rows, cols, kPi / 2.0, std::move(v));
  return tables;
}

// The environment's density, world frame: cell maxima of the radiance's channel mean
// (the error is measured on all three channels alike), plus a floor.
SphereDistribution buildEnvironmentTable(const Environment& env, int cols, unsigned threads) {
  const int rows = cols / 2;
  std::vector<double> v =
      cellMaxima(rows, cols, kPi, [&](const glm::dvec3& d) { return channelMean(env.radiance(d)); }, threads);
  const std::vector<double> e = SphereDistribution::edges(rows, kPi);
  double mass = 0.0;
  for (int r = 0; r < rows; ++r) {
    double row = 0.0;
    for (int c = 0; c < cols; ++c) row += v[static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c)];
    mass += row * (e[static_cast<std::size_t>(r)] - e[static_cast<std::size_t>(r) + 1]) * kTwoPi / cols;
  }
  const double mean = mass / (4.0 * kPi);
  if (mean > 0.0 && std::isfinite(mean)) {
    for (double& x : v) x += kEnvironmentFloor * mean;
  } else {  // black (or unusable): uniform
    std::fill(v.begin(), v.end(), 1.0);
  }
  return SphereDistribution(rows, cols, kPi, std::move(v));
}

// What a pixel's samples need, fixed over all passes.
struct PixelHit {
  std::uint32_t object = 0;
  bool lit = false;              // the view is above the shading horizon
  glm::dmat3 frame{1.0};         // local → object
  glm::dvec3 woLocal{0.0};
  glm::vec3 origin{0.0f};        // shadow-ray origin: object frame (self), world frame (scene)
  int bin0 = 0, bin1 = 0;        // brdf tables around θₒ
  double binT = 0.0;             // weight of bin1
};

}  // namespace

std::optional<ReferenceOcclusion> parseReferenceOcclusion(const std::string& name) {
  if (name == "scene") return ReferenceOcclusion::Scene;
  if (name == "self") return ReferenceOcclusion::Self;
  if (name == "none") return ReferenceOcclusion::None;
  return std::nullopt;
}

const char* referenceOcclusionName(ReferenceOcclusion occlusion) {
  switch (occlusion) {
    case ReferenceOcclusion::Scene: return "scene";
    case ReferenceOcclusion::Self: return "self";
    case ReferenceOcclusion::None: return "none";
  }
  return "unknown";
}

std::optional<ReferenceSampling> parseReferenceSampling(const std::string& name) {
  if (name == "mis") return ReferenceSampling::Mis;
  if (name == "mis-cosine") return ReferenceSampling::MisCosine;
  if (name == "environment") return ReferenceSampling::Environment;
  if (name == "brdf") return ReferenceSampling::Brdf;
  if (name == "cosine") return ReferenceSampling::Cosine;
  return std::nullopt;
}

void checkReferenceOptions(const ReferenceOptions& o) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("reference options: " + what); };
  if (o.width < 1 || o.height < 1 || o.width > 8192 || o.height > 8192) {
    bad("resolution " + std::to_string(o.width) + "×" + std::to_string(o.height) + " is outside 1..8192");
  }
  if (o.samplesPerPass < 1 || o.samplesPerPass > (1 << 20)) {
    bad("samples per pass " + std::to_string(o.samplesPerPass) + " is outside 1..2^20");
  }
  if (o.maxSamples < 2 * o.samplesPerPass || o.maxSamples > (1 << 24)) {
    bad("max samples " + std::to_string(o.maxSamples) + " must be in 2·samplesPerPass (" +
        std::to_string(2 * o.samplesPerPass) + ")..2^24: both halves need a pass");
  }
  if (!(o.tolerance >= 0.0) || !std::isfinite(o.tolerance)) bad("tolerance " + std::to_string(o.tolerance) + " must be finite and ≥ 0");
  if (o.threads > 4096) bad("threads " + std::to_string(o.threads) + " is over 4096");
  if (o.environmentTableWidth < 8 || o.environmentTableWidth > 8192 || o.environmentTableWidth % 2 != 0) {
    bad("environment table width " + std::to_string(o.environmentTableWidth) + " must be even and in 8..8192");
  }
  if (o.brdfTableThetaOut < 1 || o.brdfTableThetaOut > 256) {
    bad("brdf table view elevations " + std::to_string(o.brdfTableThetaOut) + " is outside 1..256");
  }
  if (o.brdfTableWidth < 8 || o.brdfTableWidth > 2048 || o.brdfTableWidth % 4 != 0) {
    bad("brdf table width " + std::to_string(o.brdfTableWidth) + " must be a multiple of 4 in 8..2048");
  }
  if (!(o.shadowOffset >= 0.0f) || !std::isfinite(o.shadowOffset)) bad("shadow offset must be finite and ≥ 0");
  if (o.occlusion != ReferenceOcclusion::Scene && o.occlusion != ReferenceOcclusion::Self &&
      o.occlusion != ReferenceOcclusion::None) {
    bad("unknown occlusion (valid: scene, self, none)");
  }
  (void)strategiesOf(o.sampling);
}

ReferenceResult renderReference(const Scene& scene, const ReferenceOptions& options,
                                const std::function<void(int samples, double error)>& progress) {
  checkReferenceOptions(options);
  if (scene.objects.empty()) throw std::invalid_argument("reference: the scene has no objects");
  if (!scene.environment.radiance) throw std::invalid_argument("reference: the environment has no radiance function");
  const auto start = Clock::now();
  const unsigned threads = options.threads;  // 0 = all cores (parallelFor)
  const Strategies use = strategiesOf(options.sampling);
  const Environment& env = scene.environment;

  // ---- Once per object: normals, own ray scene, brdf tables ----------------
  std::vector<PreparedObject> objects(scene.objects.size());
  for (std::size_t k = 0; k < scene.objects.size(); ++k) {
    const SceneObject& so = scene.objects[k];
    PreparedObject& p = objects[k];
    if (!so.mesh) throw std::invalid_argument("reference: object \"" + so.name + "\" has no mesh");
    if (!so.material.brdf) throw std::invalid_argument("reference: object \"" + so.name + "\" has no BRDF");
    so.mesh->validate();
    p.mesh = withNormals(so.mesh);
    p.brdf = so.material.brdf.get();
    p.rotation = so.pose.rotation();
    p.objectToWorld = so.pose.objectToWorld();
    if (options.occlusion == ReferenceOcclusion::Self) {
      p.self = std::make_unique<RayScene>(std::vector<Instance>{Instance{p.mesh.get(), glm::mat4(1.0f)}});
      p.shift = static_cast<float>(options.shadowOffset * p.mesh->bounds().radius());  // as before: a float
    }
    if (use.brdf) p.brdfTables = buildBrdfTables(*p.brdf, options, threads);
  }
  if (options.occlusion == ReferenceOcclusion::Scene) {
    // World offsets (reference.h): shadowOffset × the smallest object's world
    // radius; the per-triangle floor is taken at each hit, below.
    double rMin = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < objects.size(); ++k) {
      rMin = std::min(rMin, objects[k].mesh->bounds().radius() * scene.objects[k].pose.scale);
    }
    for (PreparedObject& p : objects) p.shift = options.shadowOffset * rMin;
  }
  std::optional<SphereDistribution> envTable;
  if (use.environment) envTable.emplace(buildEnvironmentTable(env, options.environmentTableWidth, threads));

  // ---- G-buffer: renderCpu's primary rays -----------------------------------
  std::vector<Instance> instances;
  for (std::size_t k = 0; k < objects.size(); ++k) {
    instances.push_back({objects[k].mesh.get(), glm::mat4(scene.objects[k].pose.objectToWorld())});
  }
  const RayScene primary(std::move(instances));
  const int w = options.width, h = options.height;
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  const CameraRays camera(scene.camera, w, h);  // the Haar renderer's rays, exactly

  ReferenceResult result;
  result.image = io::makeImage(w, h);
  result.objectMask.assign(pixels, 0);
  result.groundMask.assign(pixels, 0);
  std::vector<PixelHit> hits(pixels);
  const int bins = options.brdfTableThetaOut;
  parallelFor(static_cast<std::size_t>(h), threads, [&](std::size_t yy) {
    const int y = static_cast<int>(yy);
    for (int x = 0; x < w; ++x) {
      const std::size_t i = yy * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
      const glm::dvec3 dir = camera.direction(x, y);
      Ray r;
      r.origin = glm::vec3(camera.origin());
      r.direction = glm::vec3(dir);
      const std::optional<Hit> hit = primary.intersect(r);
      if (!hit) {
        if (options.environmentBackground) {
          const glm::dvec3 l = env.radiance(dir);
          for (int c = 0; c < 3; ++c) result.image.at(y, x, c) = static_cast<float>(l[c]);
        }
        continue;
      }
      result.objectMask[i] = 1;
      result.groundMask[i] = scene.objects[hit->object].ground ? 1 : 0;
      const PreparedObject& p = objects[hit->object];
      const Mesh& mesh = *p.mesh;
      const glm::uvec3 tri = mesh.triangles[hit->triangle];
      const double b[3] = {1.0 - hit->u - hit->v, hit->u, hit->v};
      const glm::dvec3 n = glm::normalize(b[0] * glm::dvec3(mesh.normals[tri.x]) + b[1] * glm::dvec3(mesh.normals[tri.y]) +
                                          b[2] * glm::dvec3(mesh.normals[tri.z]));
      const glm::dvec3 wo = glm::transpose(p.rotation) * -dir;
      PixelHit& ph = hits[i];
      ph.object = hit->object;
      double thetaOut = 0.0;
      ph.frame = shadingFrame(n, wo, thetaOut);
      ph.woLocal = glm::transpose(ph.frame) * wo;
      ph.lit = ph.woLocal.y > 0.0;
      const glm::dvec3 point = b[0] * glm::dvec3(mesh.positions[tri.x]) + b[1] * glm::dvec3(mesh.positions[tri.y]) +
                               b[2] * glm::dvec3(mesh.positions[tri.z]);
      if (options.occlusion == ReferenceOcclusion::Scene) {
        // The floor: 64 ulps of the hit point's largest coordinate, in the
        // world or in its object frame at world scale (Embree intersects
        // instances in the latter); the origin is a float.
        const glm::dvec3 world(p.objectToWorld * glm::dvec4(point, 1.0));
        const double largest = std::max(glm::length(world), glm::length(point) * scene.objects[hit->object].pose.scale);
        const double shift = std::max(p.shift, kFloatGuard * largest);
        ph.origin = glm::vec3(world + p.rotation * n * shift);
      } else {
        ph.origin = glm::vec3(point + n * p.shift);
      }
      // Linear between table centres θ_k = (k + ½)(π/2)/K, clamped at the ends.
      const double f = std::clamp(thetaOut / (kPi / 2.0) * bins - 0.5, 0.0, bins - 1.0);
      ph.bin0 = static_cast<int>(f);
      ph.bin1 = std::min(ph.bin0 + 1, bins - 1);
      ph.binT = f - ph.bin0;
    }
  });

  // ---- One sample: a direction per strategy, power heuristic ----------------
  // strata[s] = the sample's (u1, u2) for strategy s: Latin-hypercube
  // stratified over the pass (see runPass).
  using Strata = std::array<std::array<double, 2>, 3>;
  auto estimate = [&](const PixelHit& ph, Pcg32& rng, const Strata& strata) {
    const PreparedObject& p = objects[ph.object];
    // Density of ωᵢ (local l) under the tables: p(h)/(4 ωₒ·h), h = (l + ωₒ)/|l + ωₒ|.
    auto brdfTablePdf = [&](const glm::dvec3& l) {
      const glm::dvec3 sum = l + ph.woLocal;
      const double len = glm::length(sum);
      if (!(len > 0.0)) return 0.0;
      const glm::dvec3 hv = sum / len;
      const double woh = glm::dot(ph.woLocal, hv);
      if (!(woh > 0.0)) return 0.0;
      const SphereDistribution& t0 = p.brdfTables[static_cast<std::size_t>(ph.bin0)];
      const std::ptrdiff_t cell = t0.cellOf(hv);  // every table has the same cells
      return ((1.0 - ph.binT) * t0.pdfOfCell(cell) +
              ph.binT * p.brdfTables[static_cast<std::size_t>(ph.bin1)].pdfOfCell(cell)) /
             (4.0 * woh);
    };
    // The densities of every strategy in use at ω (object) = frame·l (local).
    auto pdfs = [&](const glm::dvec3& omega, const glm::dvec3& l) {
      std::array<double, 3> q{0.0, 0.0, 0.0};
      const double cosine = std::max(l.y, 0.0) / kPi;
      if (use.environment) q[0] = envTable->pdf(p.rotation * omega);
      if (use.brdf) q[1] = kDefensiveCosine * cosine + (1.0 - kDefensiveCosine) * brdfTablePdf(l);
      if (use.cosine) q[2] = cosine;
      return q;
    };
    // f(ω)·p_s/Σp_t²: the MIS-weighted contribution of strategy s.
    auto contribution = [&](const glm::dvec3& omega, const glm::dvec3& l, int s) {
      if (!(l.y > 0.0)) return glm::dvec3(0.0);
      const std::array<double, 3> q = pdfs(omega, l);
      const double ps = q[static_cast<std::size_t>(s)];
      const double sum2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2];
      if (!(ps > 0.0) || !(sum2 > 0.0)) return glm::dvec3(0.0);
      const glm::dvec3 rho = p.brdf->evaluate(l, ph.woLocal);
      if (!(rho.x > 0.0 || rho.y > 0.0 || rho.z > 0.0)) return glm::dvec3(0.0);
      const glm::dvec3 f = env.radiance(p.rotation * omega) * rho * l.y;
      if (!(f.x > 0.0 || f.y > 0.0 || f.z > 0.0)) return glm::dvec3(0.0);
      if (options.occlusion != ReferenceOcclusion::None) {
        Ray shadow;
        shadow.origin = ph.origin;
        if (options.occlusion == ReferenceOcclusion::Scene) {
          shadow.direction = glm::vec3(p.rotation * omega);  // world frame: the posed objects of `primary`
          if (primary.occluded(shadow)) return glm::dvec3(0.0);
        } else {
          shadow.direction = glm::vec3(omega);
          if (p.self->occluded(shadow)) return glm::dvec3(0.0);
        }
      }
      return f * (ps / sum2);
    };
    auto cosineLocal = [](double u1, double u2) {
      const double r = std::sqrt(u1), phi = kTwoPi * u2;
      return glm::dvec3(r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1)), r * std::cos(phi));
    };

    glm::dvec3 sum(0.0);
    if (use.environment) {
      const double u1 = strata[0][0], u2 = strata[0][1], u3 = rng.uniform(), u4 = rng.uniform();
      const glm::dvec3 omega = glm::transpose(p.rotation) * envTable->sample(u1, u2, u3, u4).direction;
      sum += contribution(omega, glm::transpose(ph.frame) * omega, 0);
    }
    if (use.brdf) {
      const double u0 = rng.uniform(), ub = rng.uniform();
      const double u1 = strata[1][0], u2 = strata[1][1], u3 = rng.uniform(), u4 = rng.uniform();
      glm::dvec3 l;
      if (u0 < kDefensiveCosine) {
        l = cosineLocal(u1, u2);
      } else {
        const int bin = ub < ph.binT ? ph.bin1 : ph.bin0;
        const glm::dvec3 hv = p.brdfTables[static_cast<std::size_t>(bin)].sample(u1, u2, u3, u4).direction;
        l = 2.0 * glm::dot(ph.woLocal, hv) * hv - ph.woLocal;  // may fall below the horizon: then it adds 0
      }
      sum += contribution(ph.frame * l, l, 1);
    }
    if (use.cosine) {
      const double u1 = strata[2][0], u2 = strata[2][1];
      const glm::dvec3 l = cosineLocal(u1, u2);
      sum += contribution(ph.frame * l, l, 2);
    }
    return sum;
  };

  // ---- Passes into two halves ----------------------------------------------
  // Within a pass, each strategy's first two dimensions (which pick the cell
  // of its table, or the cosine direction) are Latin-hypercube stratified
  // over the pass's n samples: u1 = (k + ξ)/n, u2 = (π(k) + ξ')/n for a
  // random permutation π. Every sample stays uniform, so the estimate stays
  // unbiased, and passes stay independent, so the half-images do; but how
  // many samples land on the sun in a pass no longer varies (most of the
  // variance under a small bright source).
  std::array<std::vector<double>, 2> halves{std::vector<double>(pixels * 3, 0.0), std::vector<double>(pixels * 3, 0.0)};
  const int n = options.samplesPerPass;
  auto runPass = [&](int pass) {
    std::vector<double>& acc = halves[static_cast<std::size_t>(pass % 2)];
    const std::uint64_t passKey = splitMix64(options.seed ^ splitMix64(static_cast<std::uint64_t>(pass)));
    parallelFor(static_cast<std::size_t>(h), threads, [&](std::size_t yy) {
      std::array<std::vector<int>, 3> perm;
      for (auto& v : perm) v.resize(static_cast<std::size_t>(n));
      for (int x = 0; x < w; ++x) {
        const std::size_t i = yy * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
        if (!result.objectMask[i] || !hits[i].lit) continue;
        Pcg32 rng(splitMix64(passKey + i), i);
        for (auto& v : perm) {  // Fisher–Yates
          for (int k = 0; k < n; ++k) v[static_cast<std::size_t>(k)] = k;
          for (int k = n - 1; k > 0; --k) {
            const auto j = static_cast<int>(rng.next() % static_cast<std::uint32_t>(k + 1));
            std::swap(v[static_cast<std::size_t>(k)], v[static_cast<std::size_t>(j)]);
          }
        }
        const double inv = 1.0 / n;
        glm::dvec3 s(0.0);
        for (int k = 0; k < n; ++k) {
          Strata strata;
          for (std::size_t t = 0; t < 3; ++t) {
            strata[t] = {std::min((k + rng.uniform()) * inv, kBelowOne),
                         std::min((perm[t][static_cast<std::size_t>(k)] + rng.uniform()) * inv, kBelowOne)};
          }
          s += estimate(hits[i], rng, strata);
        }
        for (int c = 0; c < 3; ++c) acc[3 * i + static_cast<std::size_t>(c)] += s[c];
      }
    });
  };
  auto halfError = [&] {
    double diff2 = 0.0, mean = 0.0;
    std::size_t count = 0;
    for (std::size_t i = 0; i < pixels; ++i) {
      if (!result.objectMask[i]) continue;
      for (std::size_t c = 0; c < 3; ++c) {
        const double a = halves[0][3 * i + c], b = halves[1][3 * i + c];  // equal counts: sums compare as means
        diff2 += (a - b) * (a - b);
        mean += 0.5 * (a + b);
        ++count;
      }
    }
    if (count == 0 || diff2 == 0.0) return 0.0;
    if (!(mean > 0.0)) return std::numeric_limits<double>::infinity();
    return std::sqrt(diff2 * static_cast<double>(count)) / mean;  // sqrt(mean d²)/mean m; the common count cancels
  };

  int samples = 0;
  double error = 0.0;
  for (int pass = 0;; pass += 2) {
    runPass(pass);
    runPass(pass + 1);
    samples += 2 * n;
    error = halfError();
    if (progress) progress(samples, error);
    if (error <= options.tolerance || samples + 2 * n > options.maxSamples) break;
  }

  const double inv = 1.0 / samples;
  for (std::size_t i = 0; i < pixels; ++i) {
    if (!result.objectMask[i]) continue;
    for (std::size_t c = 0; c < 3; ++c) result.image.rgb[3 * i + c] = static_cast<float>((halves[0][3 * i + c] + halves[1][3 * i + c]) * inv);
  }
  result.samples = samples;
  result.halfError = error;
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace haarcast::render
