#include "list_flags.h"

#include <iterator>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "haarcast/core/shared_smooth.h"
#include "haarcast/render/renderer.h"

namespace haarcast::app {

std::vector<std::string> splitList(const std::string& text, const char* flag) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item.empty()) throw std::invalid_argument(std::string(flag) + " \"" + text + "\" has an empty item");
    out.push_back(item);
  }
  if (out.empty()) throw std::invalid_argument(std::string(flag) + " is empty");
  return out;
}

int parseIntIn(const std::string& item, const char* flag, int lo, int hi) {
  std::size_t used = 0;
  int v = 0;
  try {
    v = std::stoi(item, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (item.empty() || used != item.size() || v < lo || v > hi) {
    throw std::invalid_argument(std::string(flag) + ": \"" + item + "\" is not an integer in " + std::to_string(lo) +
                                ".." + std::to_string(hi));
  }
  return v;
}

std::vector<int> parseIntList(const std::string& text, const char* flag, int lo, int hi) {
  std::vector<int> out;
  for (const std::string& item : splitList(text, flag)) out.push_back(parseIntIn(item, flag, lo, hi));
  return out;
}

std::vector<std::pair<int, int>> parseSizeList(const std::string& text, const char* flag) {
  std::vector<std::pair<int, int>> out;
  for (const std::string& item : splitList(text, flag)) {
    const std::size_t x = item.find('x');
    const int w = parseIntIn(item.substr(0, x), flag, 1, render::kMaxFrameSide);
    out.emplace_back(w, x == std::string::npos ? w : parseIntIn(item.substr(x + 1), flag, 1, render::kMaxFrameSide));
  }
  return out;
}

std::vector<RotationMethod> parseMethodList(const std::string& text, const char* flag, bool allowAll) {
  std::vector<RotationMethod> out;
  for (const std::string& item : splitList(text, flag)) {
    if (allowAll && item == "all") {
      out.insert(out.end(), std::begin(kAllPixelMethods), std::end(kAllPixelMethods));
      continue;
    }
    const auto m = parseRotationMethod(item);
    if (!m) {
      throw std::invalid_argument(std::string(flag) + ": \"" + item + "\" is not one of " + pixelMethodNames() +
                                  (allowAll ? " or all" : ""));
    }
    out.push_back(*m);
  }
  return out;
}

render::RayMode parseRayModeFlag(const std::string& text) {
  if (const std::optional<render::RayMode> mode = render::parseRayMode(text)) return *mode;
  throw std::invalid_argument("--rays must be auto, device or host (got \"" + text + "\")");
}

std::string sumToleranceHelp() {
  return "fused: sum a cell of 4×4 directions at one direction where the BRDF slice's detail there is at most "
         "this fraction of its mean, the rest direction by direction (0 = every direction; docs/design.md)";
}

std::string smoothSumHelp() {
  return "fused: take a pixel's sum (the light's rest × visibility × BRDF) from its neighbours where their mirror "
         "directions are within half the lobe and their sums agree within this fraction of what they show, coarse to "
         "fine from every " + std::to_string(shared::kSmoothSumSpacing) +
         "th pixel; point lights, shadows between objects and mirror cores stay each pixel's own "
         "(0 = sum every pixel; docs/design.md)";
}

std::vector<float> parseToleranceList(const std::string& text, const char* flag) {
  std::vector<float> out;
  for (const std::string& item : splitList(text, flag)) {
    std::size_t used = 0;
    float t = -1.0f;
    try {
      t = std::stof(item, &used);
    } catch (const std::exception&) {
    }
    if (used != item.size() || !(t >= 0.0f && t <= 1.0f)) {
      throw std::invalid_argument(std::string(flag) + ": \"" + item + "\" is not a number in 0..1");
    }
    out.push_back(t);
  }
  return out;
}

std::string rayModeHelp() {
  return "Vulkan: where the shadow rays are traced: auto (the device on a GPU that traces rays, else the host), "
         "device (a ray-tracing pipeline; refused where the device has none) or host (Embree)";
}

}  // namespace haarcast::app
