#include "haarcast/client/build_progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace haarcast::client {
namespace {

// A plain line at most this often within a stage, or when this many more
// percent are done than at the last one (logs and CI read these).
constexpr double kLineSeconds = 5.0;
constexpr int kLinePercentStep = 10;

// From done and total, not `fraction`: 29 / 100 is 28.999… as a double.
int percentOf(const v1::BuildProgress& p) {
  if (p.total() == 0) return -1;
  if (p.done() >= p.total()) return 100;
  const long double percent = static_cast<long double>(p.done()) * 100 / static_cast<long double>(p.total());
  return std::min(99, static_cast<int>(percent));  // never 100 before the end
}

}  // namespace

std::string formatDuration(double seconds) {
  char b[48];
  if (!(seconds >= 0.0)) seconds = 0.0;
  if (seconds < 9.95) {
    std::snprintf(b, sizeof b, "%.1f s", seconds);
  } else if (seconds < 59.5) {
    std::snprintf(b, sizeof b, "%.0f s", seconds);
  } else if (seconds < 3599.5) {
    const long s = std::lround(seconds);
    std::snprintf(b, sizeof b, "%ld min %02ld s", s / 60, s % 60);
  } else {
    const long m = std::lround(std::min(seconds, 1e9) / 60.0);
    std::snprintf(b, sizeof b, "%ld h %02ld min", m / 60, m % 60);
  }
  return b;
}

std::string buildProgressText(const v1::BuildProgress& p) {
  // The server's text goes to a terminal: no escape sequence gets through.
  std::string out;
  for (const char ch : p.stage().substr(0, 120)) {
    const auto c = static_cast<unsigned char>(ch);
    out += c < 0x20 || c == 0x7F ? '?' : ch;
  }
  if (out.empty()) out = "renderer";
  const int percent = percentOf(p);
  if (percent >= 0) {
    char pct[16];
    std::snprintf(pct, sizeof pct, " %3d %%", percent);
    out += pct;
  }
  if (p.stages_size() > 0) {
    // The server's plan: the whole build's share, the step counted in it,
    // and the build's time left.
    const double f = std::isfinite(p.build_fraction()) ? std::clamp(p.build_fraction(), 0.0, 1.0) : 0.0;
    char build[64];
    std::snprintf(build, sizeof build, " · build %d %%", std::min(99, static_cast<int>(f * 100.0)));
    out += build;
    for (int i = 0; i < p.stages_size(); ++i) {
      if (p.stages(i) != p.stage()) continue;
      out += " (step " + std::to_string(i + 1) + " of " + std::to_string(p.stages_size()) + ")";
      break;
    }
    const double buildLeft = p.estimated_build_seconds_left();
    if (std::isfinite(buildLeft) && buildLeft > 0.0) out += ", ~" + formatDuration(buildLeft) + " left";
    return out;
  }
  const double left = p.estimated_stage_seconds_left();
  if (percent >= 0 && percent < 100 && std::isfinite(left) && left > 0.0) {
    out += " (~" + formatDuration(left) + " left in this stage)";
  }
  return out;
}

void BuildProgressDisplay::update(const v1::BuildProgress& p, double now) {
  lastElapsed_ = std::isfinite(p.elapsed_seconds()) ? p.elapsed_seconds() : 0.0;
  lastAt_ = now;
  const std::string text = "building: " + buildProgressText(p);
  const int percent = percentOf(p);
  if (terminal_) {
    sink_("\r" + text + "\x1b[K");
    lineOpen_ = true;
  } else {
    const bool newStage = !shown_ || p.stage_index() != lastStage_;
    if (!newStage && percent - lastPercent_ < kLinePercentStep && now - lastLineAt_ < kLineSeconds) return;
    sink_(text + "\n");
    lastLineAt_ = now;
  }
  shown_ = true;
  lastStage_ = p.stage_index();
  lastPercent_ = percent;
}

void BuildProgressDisplay::ready(double now) {
  if (!shown_) return;
  const std::string text = "building: ready after " + formatDuration(lastElapsed_ + std::max(0.0, now - lastAt_));
  sink_(terminal_ ? "\r" + text + "\x1b[K\n" : text + "\n");
  lineOpen_ = false;
  shown_ = false;
  lastPercent_ = -1;
}

void BuildProgressDisplay::endLine() {
  if (lineOpen_) sink_("\n");
  lineOpen_ = false;
}

}  // namespace haarcast::client
