// Flag values that several commands take (--sizes, --levels, --clients,
// --methods, --sum-tolerance, --rays): one parser, one wording of every
// error, which names the flag, the item and what is allowed.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "haarcast/core/rotation.h"
#include "haarcast/render/backend_names.h"

namespace haarcast::app {

// "a,b,c" → {"a", "b", "c"}; an empty list or item is an error.
std::vector<std::string> splitList(const std::string& text, const char* flag);

// One whole integer in lo..hi.
int parseIntIn(const std::string& item, const char* flag, int lo, int hi);

// "4,5,6" with every item in lo..hi.
std::vector<int> parseIntList(const std::string& text, const char* flag, int lo, int hi);

// "256" (square) or "1920x1080", comma-separated; each side 1..kMaxFrameSide.
std::vector<std::pair<int, int>> parseSizeList(const std::string& text, const char* flag);

// Per-pixel method names (DESIGN.md), comma-separated; "all" (when allowed)
// stands for every method.
std::vector<RotationMethod> parseMethodList(const std::string& text, const char* flag, bool allowAll);

// --sum-tolerance (RenderOptions::sumTolerance): its --help text, and a
// comma-separated list of them, each in 0..1 (bench-frame times each).
std::string sumToleranceHelp();
// --smooth-sum (RenderOptions::smoothSumTolerance): its --help text.
std::string smoothSumHelp();
std::vector<float> parseToleranceList(const std::string& text, const char* flag);

// --rays: auto, device or host (render::RayMode).
render::RayMode parseRayModeFlag(const std::string& text);
// Its --help text.
std::string rayModeHelp();

}  // namespace haarcast::app
