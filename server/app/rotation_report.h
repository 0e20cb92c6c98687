// `haarcast rotation-report`: every rotation method, measured side by side in
// one run on the same lobes, rotations and light (DESIGN.md "Measurements").
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "haarcast/core/rotation.h"
#include "progress.h"

namespace haarcast::app {

struct RotationReportOptions {
  int level = 5;
  int rotations = 50;
  std::uint32_t seed = 1;
  int supersampling = 4;        // per pixel, for the lobes and the exact references
  int storageThetaSamples = 16;  // slice-table size for stored_bytes
  RotatorOptions rotator;
};

struct MethodScores {
  double psnrMapVsExact = 0.0;
  double psnrRenderVsExact = 0.0;
  double psnrRenderVsSpatial = 0.0;
  double nsPerRotation = 0.0;
  std::size_t storedBytes = 0;
};

struct RotationReport {
  int level = 0;
  int rotations = 0;
  std::vector<std::string> lobes;
  // method name → scores averaged over lobes (PSNR in dB averaged, as the
  // seed averages its tables), and per lobe.
  std::map<std::string, MethodScores> methods;
  std::map<std::string, std::map<std::string, MethodScores>> perLobe;
  // The variants of `haar`, scored the same way, and per lobe.
  std::map<std::string, MethodScores> haarVariants;
  std::map<std::string, std::map<std::string, MethodScores>> haarVariantsPerLobe;
};

// Throws std::invalid_argument naming the bad option. progress(message) gets
// one line per finished method (may be empty); stages(stage, done, total)
// counts the rotations of the two long stages, "rotation-report references"
// and "rotation-report scoring" (may be empty).
RotationReport runRotationReport(const RotationReportOptions& options,
                                 const std::function<void(const std::string&)>& progress = {},
                                 const StageProgress& stages = {});

nlohmann::json toJson(const RotationReport& report);
std::string toText(const RotationReport& report);

}  // namespace haarcast::app
