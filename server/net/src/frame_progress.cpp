#include "haarcast/net/frame_progress.h"

#include <algorithm>

namespace haarcast::net {
namespace {

double secondsBetween(FrameProgressTracker::Clock::time_point a, FrameProgressTracker::Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

double totalSeconds(const std::vector<render::StageTime>& stages) {
  double total = 0.0;
  for (const render::StageTime& s : stages) total += std::max(0.0, s.seconds);
  return total;
}

}  // namespace

std::optional<double> frameFraction(std::string_view stage, double stageFraction,
                                    const std::vector<render::StageTime>& last) {
  if (stage == kQueuedStage) return 0.0;
  const double total = totalSeconds(last);
  const auto it = std::find_if(last.begin(), last.end(), [&](const render::StageTime& s) { return s.name == stage; });
  if (it == last.end() || !(total > 0.0)) return std::nullopt;
  double before = 0.0;
  for (auto s = last.begin(); s != it; ++s) before += std::max(0.0, s->seconds);
  return std::clamp((before + std::clamp(stageFraction, 0.0, 1.0) * std::max(0.0, it->seconds)) / total, 0.0, 1.0);
}

std::vector<render::StageTime> defaultStageShares(RotationMethod method) {
  // Shares of a 256² frame of the built-in scene on the CPU backend
  // (bench-frame --sizes 256 --levels auto --antialias on, medians of 3),
  // rounded; the light and the Vulkan host's shadow rays at a few percent.
  switch (method) {
    case RotationMethod::Fused:
      return {{"light", 0.02}, {"gbuffer", 0.02}, {"rotation-input", 0.01}, {"shadow-rays", 0.02}, {"fused", 0.91}, {"tonemap", 0.02}};
    case RotationMethod::Splitsum:
      return {{"light", 0.01}, {"gbuffer", 0.30}, {"rotation-input", 0.18}, {"splitsum", 0.40}, {"tonemap", 0.11}};
    default:
      return {{"light", 0.01}, {"gbuffer", 0.01}, {"rotation-input", 0.01}, {"rotation", 0.80}, {"triple-product", 0.16},
              {"tonemap", 0.01}};
  }
}

FrameProgressTracker::FrameProgressTracker(Clock::time_point ordered, RotationMethod method,
                                           std::vector<render::StageTime> last, std::size_t lastPixels,
                                           std::size_t pixels)
    : ordered_(ordered), queuedUntil_(ordered) {
  if (last.empty() || !(totalSeconds(last) > 0.0)) {
    last_ = defaultStageShares(method);
  } else {
    last_ = std::move(last);
    // Render time grows with pixels (the per-pixel passes are most of it).
    if (lastPixels > 0) expectedSeconds_ = totalSeconds(last_) * static_cast<double>(pixels) / static_cast<double>(lastPixels);
  }
}

std::optional<FrameProgressUpdate> FrameProgressTracker::poll(const render::StageMark& mark, Clock::time_point now) {
  const char* stage = mark.current();
  // The render started after the last poll that saw the frame queued (the
  // order, if none did): its time so far errs long, never short.
  if (!stage) queuedUntil_ = now;
  const double elapsed = secondsBetween(ordered_, now);
  if (elapsed < kFrameProgressAfterSeconds) return std::nullopt;
  if (lastSent_ && secondsBetween(*lastSent_, now) < kFrameProgressIntervalSeconds) return std::nullopt;
  lastSent_ = now;
  FrameProgressUpdate u;
  u.stage = stage ? stage : kQueuedStage;
  u.stageFraction = stage ? mark.fraction() : 0.0;
  if (const auto f = frameFraction(u.stage, u.stageFraction, last_)) fraction_ = std::max(fraction_, *f);
  u.fraction = fraction_;
  u.elapsedSeconds = elapsed;
  if (stage) {
    const double rendering = secondsBetween(queuedUntil_, now);
    // The rate so far once it says something (a tenth of the frame); before,
    // the last frame's time scaled to this one's pixels, less what has passed.
    if (fraction_ >= 0.1) {
      u.secondsLeft = rendering * (1.0 - fraction_) / fraction_;
    } else if (expectedSeconds_ > 0.0) {
      u.secondsLeft = std::max(0.0, expectedSeconds_ - rendering);
    }
  }
  return u;
}

}  // namespace haarcast::net
