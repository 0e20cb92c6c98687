#include "rotation_report.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <glm/mat3x3.hpp>

#include "haarcast/assets/procedural_environment.h"
#include "haarcast/core/brdf.h"
#include "haarcast/core/brdf_slices.h"
#include "haarcast/core/metrics.h"
#include "haarcast/core/rotate_haar.h"
#include "haarcast/core/triple_product.h"

namespace haarcast::app {
namespace {

// A lobe is one BRDF slice: ρ(ωᵢ, ωₒ)·cos θᵢ in the local frame at θₒ = 30°.
constexpr double kLobeThetaOut = kPi / 6.0;

struct Lobe {
  std::string name;
  std::unique_ptr<Brdf> brdf;
};

std::vector<Lobe> reportLobes() {
  std::vector<Lobe> lobes;
  lobes.push_back({"lambert", makeLambert(glm::dvec3(1.0))});
  lobes.push_back({"phong64", makePhong(glm::dvec3(0.0), glm::dvec3(1.0), 64.0)});
  lobes.push_back({"phong512", makePhong(glm::dvec3(0.0), glm::dvec3(1.0), 512.0)});
  return lobes;
}

// The report's light: the built-in HDR environment (a small sun among
// others), channel mean, solid angle folded in, every coefficient kept.
SparseHaar reportLight(int level) {
  const auto env = assets::proceduralEnvironment(level, 8);
  SphereMap mean(level);
  for (std::size_t i = 0; i < mean.pixelCount(); ++i)
    mean.values()[i] = (env[0].values()[i] + env[1].values()[i] + env[2].values()[i]) / 3.0f;
  return SparseHaar::fromDense(forwardHaar(mean.weightedBySolidAngle()));
}

// V = 1 everywhere: only the scaling coefficient, M.
SparseHaar unitVisibility(int level) {
  SparseHaar v;
  v.level = level;
  v.index = {0};
  v.value = {static_cast<float>(mapSize(level))};
  return v;
}

void appendPixels(const HaarMap& m, std::vector<float>& out) {
  const SphereMap p = inverseHaar(m);
  out.insert(out.end(), p.values().begin(), p.values().end());
}

struct Accumulator {
  std::vector<float> mapTest, mapExact;
  std::vector<double> renderTest, renderExact, renderSpatial;
  double seconds = 0.0;
  int calls = 0;

  MethodScores scores() const {
    MethodScores s;
    s.psnrMapVsExact = compareSignals(mapExact, mapTest).psnr;
    s.psnrRenderVsExact = compareSignals(renderExact, renderTest).psnr;
    s.psnrRenderVsSpatial = compareSignals(renderSpatial, renderTest).psnr;
    s.nsPerRotation = seconds * 1e9 / calls;
    return s;
  }
};

MethodScores averageOverLobes(const std::map<std::string, MethodScores>& perLobe, double ns, std::size_t bytes) {
  MethodScores avg;
  for (const auto& [name, s] : perLobe) {
    avg.psnrMapVsExact += s.psnrMapVsExact / static_cast<double>(perLobe.size());
    avg.psnrRenderVsExact += s.psnrRenderVsExact / static_cast<double>(perLobe.size());
    avg.psnrRenderVsSpatial += s.psnrRenderVsSpatial / static_cast<double>(perLobe.size());
  }
  avg.nsPerRotation = ns;
  avg.storedBytes = bytes;
  return avg;
}

nlohmann::json psnrJson(double db) {
  // JSON has no infinity: an exact match is the string "inf".
  if (std::isinf(db)) return db > 0 ? "inf" : "-inf";
  return db;
}

nlohmann::json scoresJson(const MethodScores& s) {
  return {{"psnr_map_vs_exact", psnrJson(s.psnrMapVsExact)},
          {"psnr_render_vs_exact", psnrJson(s.psnrRenderVsExact)},
          {"psnr_render_vs_spatial", psnrJson(s.psnrRenderVsSpatial)},
          {"ns_per_rotation", s.nsPerRotation},
          {"stored_bytes", s.storedBytes}};
}

}  // namespace

RotationReport runRotationReport(const RotationReportOptions& o, const std::function<void(const std::string&)>& progress,
                                 const StageProgress& stages) {
  if (o.level < 2 || o.level > 7) {
    throw std::invalid_argument("rotation-report: --level must be between 2 and 7 (got " + std::to_string(o.level) + ")");
  }
  if (o.rotations < 1 || o.rotations > 100000) {
    throw std::invalid_argument("rotation-report: --rotations must be between 1 and 100000 (got " +
                                std::to_string(o.rotations) + ")");
  }
  auto say = [&](const std::string& line) {
    if (progress) progress(line);
  };
  auto step = [&](const char* stage, std::size_t done, std::size_t total) {
    if (stages) stages(stage, done, total);
  };
  const int level = o.level;
  const std::vector<Lobe> lobes = reportLobes();
  const std::vector<EulerYXY> rotations = randomRotations(o.rotations, o.seed);
  const SparseHaar light = reportLight(level);
  const SparseHaar visibility = unitVisibility(level);
  auto render = [&](const HaarMap& brdf) { return tripleProduct(light, brdf, visibility); };

  std::vector<HaarMap> slices;
  for (const Lobe& l : lobes) slices.push_back(forwardHaar(sliceMap(*l.brdf, kLobeThetaOut, 0, level, o.supersampling)));

  // References, once: the analytic rotation and `spatial`.
  std::vector<std::vector<HaarMap>> exact(lobes.size()), spatial(lobes.size());
  const glm::dvec3 wo = sphericalToDirection(kLobeThetaOut, 0.0);
  const std::size_t referenceCount = lobes.size() * rotations.size();
  step("rotation-report references", 0, referenceCount);
  for (std::size_t l = 0; l < lobes.size(); ++l) {
    for (const EulerYXY& r : rotations) {
      const glm::dmat3 rt = glm::transpose(rotationMatrix(r));
      exact[l].push_back(forwardHaar(supersampledMap(level, o.supersampling, [&](const glm::dvec3& d) {
        const glm::dvec3 local = rt * d;
        return local.y > 0.0 ? lobes[l].brdf->evaluate(local, wo).x * local.y : 0.0;
      })));
      spatial[l].push_back(rotateSpatial(slices[l], r));
      step("rotation-report references", l * rotations.size() + spatial[l].size(), referenceCount);
    }
  }
  say("references ready: " + std::to_string(rotations.size()) + " rotations × " + std::to_string(lobes.size()) + " lobes");

  // Every method and every haar variant rotates every lobe by every rotation.
  constexpr HaarVariant kVariants[] = {HaarVariant::Faithful, HaarVariant::Local, HaarVariant::Refined};
  const std::size_t scoreCount = (std::size(kAllRotationMethods) + std::size(kVariants)) * referenceCount;
  std::size_t scored = 0;
  step("rotation-report scoring", 0, scoreCount);
  // Scores one rotator over every lobe and rotation.
  auto score = [&](const SliceRotator& rotator, std::map<std::string, MethodScores>& perLobe, double& ns) {
    double seconds = 0.0;
    int calls = 0;
    HaarMap out;
    for (std::size_t l = 0; l < lobes.size(); ++l) {
      Accumulator acc;
      for (std::size_t k = 0; k < rotations.size(); ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        rotator.rotate(l, rotations[k], out);
        acc.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        ++acc.calls;
        appendPixels(out, acc.mapTest);
        appendPixels(exact[l][k], acc.mapExact);
        acc.renderTest.push_back(render(out));
        acc.renderExact.push_back(render(exact[l][k]));
        acc.renderSpatial.push_back(render(spatial[l][k]));
        step("rotation-report scoring", ++scored, scoreCount);
      }
      perLobe[lobes[l].name] = acc.scores();
      seconds += acc.seconds;
      calls += acc.calls;
    }
    ns = seconds * 1e9 / calls;
  };

  // Storage is for a slice table of T θₒ samples of one channel.
  const auto phong = makePhong(glm::dvec3(0.0), glm::dvec3(1.0), 64.0);
  SliceTableOptions tableOptions;
  tableOptions.level = level;
  tableOptions.thetaSamples = o.storageThetaSamples;
  tableOptions.supersampling = 1;
  const std::vector<HaarMap> storageSlices = BrdfSliceTable::build(*phong, tableOptions).channelSlices(0);

  RotationReport report;
  report.level = level;
  report.rotations = o.rotations;
  for (const Lobe& l : lobes) report.lobes.push_back(l.name);
  for (RotationMethod method : kAllRotationMethods) {
    const std::string name(methodName(method));
    const auto t0 = std::chrono::steady_clock::now();
    const auto rotator = makeRotator(method, slices, o.rotator);
    const double setup = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    double ns = 0.0;
    score(*rotator, report.perLobe[name], ns);
    const std::size_t bytes = makeRotator(method, storageSlices, o.rotator)->storedBytes();
    report.methods[name] = averageOverLobes(report.perLobe[name], ns, bytes);
    char line[160];
    std::snprintf(line, sizeof line, "%-8s done (precompute %.2f s, %.0f ns per rotation)", name.c_str(), setup, ns);
    say(line);
  }
  for (HaarVariant v : kVariants) {
    RotatorOptions ro = o.rotator;
    ro.haarVariant = v;
    const std::string name(variantName(v));
    auto& perLobe = report.haarVariantsPerLobe[name];
    double ns = 0.0;
    score(*makeRotator(RotationMethod::Haar, slices, ro), perLobe, ns);
    report.haarVariants[name] = averageOverLobes(perLobe, ns, report.methods["haar"].storedBytes);
  }
  say("haar variants done");
  return report;
}

nlohmann::json toJson(const RotationReport& r) {
  nlohmann::json j;
  j["level"] = r.level;
  j["rotations"] = r.rotations;
  for (const auto& [name, s] : r.methods) j["methods"][name] = scoresJson(s);
  for (const auto& [name, lobes] : r.perLobe)
    for (const auto& [lobe, s] : lobes) j["lobes"][lobe][name] = scoresJson(s);
  for (const auto& [name, s] : r.haarVariants) j["haar_variants"][name] = scoresJson(s);
  for (const auto& [name, lobes] : r.haarVariantsPerLobe)
    for (const auto& [lobe, s] : lobes) j["lobes"][lobe]["haar/" + name] = scoresJson(s);
  return j;
}

std::string toText(const RotationReport& r) {
  std::ostringstream out;
  char line[200];
  std::snprintf(line, sizeof line, "rotation report: level %d (%d×%d), %d random rotations, lobes:", r.level,
                mapSize(r.level), mapSize(r.level), r.rotations);
  out << line;
  for (const auto& l : r.lobes) out << ' ' << l;
  out << "\nPSNR in dB (mean over lobes); render = ∫ light·lobe dω against the built-in HDR sky\n\n";
  std::snprintf(line, sizeof line, "%-16s %12s %14s %16s %14s %14s\n", "method", "map/exact", "render/exact",
                "render/spatial", "ns/rotation", "stored bytes");
  out << line;
  auto row = [&](const std::string& name, const MethodScores& s) {
    std::snprintf(line, sizeof line, "%-16s %12.2f %14.2f %16.2f %14.0f %14zu\n", name.c_str(), s.psnrMapVsExact,
                  s.psnrRenderVsExact, s.psnrRenderVsSpatial, s.nsPerRotation, s.storedBytes);
    out << line;
  };
  for (const auto& [name, s] : r.methods) row(name, s);
  for (const auto& [name, s] : r.haarVariants) row("haar/" + name, s);
  out << "\n(stored bytes: a 16-sample slice table of one channel; inf = identical to float precision)\n";
  return out.str();
}

}  // namespace haarcast::app
