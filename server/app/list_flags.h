// Comma-separated flag values that `bench-frame` and `loadtest` both take
// (--sizes, --levels, --clients, --methods): one parser, one wording of
// every error, which names the flag, the item and what is allowed.
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

// --rays: auto, device or host (render::RayMode).
render::RayMode parseRayModeFlag(const std::string& text);
// Its --help text.
std::string rayModeHelp();

}  // namespace haarcast::app
