#include "haarcast/net/build_progress.h"

#include <algorithm>

#include "haarcast/net/messages.h"

namespace haarcast::net {
namespace {

double secondsBetween(BuildProgressTracker::Clock::time_point a, BuildProgressTracker::Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// The length of the well-formed UTF-8 sequence at text[i], or 0 (a stray
// continuation byte, a sequence cut short, an overlong or surrogate form):
// a proto3 string must be valid UTF-8, or the client's parser refuses the
// whole message.
std::size_t utf8SequenceAt(std::string_view text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char c = byte(i);
  if (c < 0x80) return 1;
  std::size_t n = 0;
  unsigned char low = 0x80, high = 0xBF;  // the allowed range of the second byte
  if (c >= 0xC2 && c <= 0xDF) {
    n = 2;
  } else if (c >= 0xE0 && c <= 0xEF) {
    n = 3;
    if (c == 0xE0) low = 0xA0;   // no overlong forms
    if (c == 0xED) high = 0x9F;  // no surrogates
  } else if (c >= 0xF0 && c <= 0xF4) {
    n = 4;
    if (c == 0xF0) low = 0x90;
    if (c == 0xF4) high = 0x8F;  // nothing above U+10FFFF
  } else {
    return 0;
  }
  if (i + n > text.size() || byte(i + 1) < low || byte(i + 1) > high) return 0;
  for (std::size_t k = 2; k < n; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
  }
  return n;
}

// A word that names a file keeps only its last part: "/srv/scenes/bunny.ply"
// → "bunny.ply", "C:\x\y" → "y".
std::string lastPathPart(std::string word) {
  while (!word.empty() && (word.back() == '/' || word.back() == '\\')) word.pop_back();
  const auto cut = word.find_last_of("/\\");
  return cut == std::string::npos ? word : word.substr(cut + 1);
}

}  // namespace

double BuildProgressUpdate::fraction() const {
  if (total == 0) return 0.0;
  return std::clamp(static_cast<double>(done) / static_cast<double>(total), 0.0, 1.0);
}

BuildProgressTracker::BuildProgressTracker(Clock::time_point started, double minIntervalSeconds, render::BuildPlan plan)
    : started_(started),
      minInterval_(std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(std::max(0.0, minIntervalSeconds)))),
      plan_(std::move(plan)),
      planWork_(plan_.totalWork()) {}

std::optional<BuildProgressUpdate> BuildProgressTracker::step(const std::string& stage, std::size_t done, std::size_t total,
                                                              Clock::time_point now) {
  auto it = std::find_if(stages_.begin(), stages_.end(), [&](const Stage& s) { return s.name == stage; });
  const bool isNew = it == stages_.end();
  if (isNew) {
    Stage s{stage, now, done, std::nullopt, 0.0};
    const auto p = std::find_if(plan_.stages.begin(), plan_.stages.end(), [&](const render::PlannedStage& q) { return q.name == stage; });
    if (p != plan_.stages.end()) s.planned = static_cast<std::size_t>(p - plan_.stages.begin());
    stages_.push_back(std::move(s));
    it = std::prev(stages_.end());
  }
  // Every report moves the build's fraction, published or not (Eq. in the
  // class comment: whole stages before it, this one by its own fraction).
  const double stageFraction = total ? std::clamp(static_cast<double>(done) / static_cast<double>(total), 0.0, 1.0) : 0.0;
  it->fraction = std::max(it->fraction, stageFraction);
  if (it->planned && planWork_ > 0.0) {
    double before = 0.0;
    for (std::size_t j = 0; j < *it->planned; ++j) before += plan_.stages[j].work;
    buildFraction_ = std::max(buildFraction_, std::min(1.0, (before + it->fraction * plan_.stages[*it->planned].work) / planWork_));
  }
  if (!isNew && lastPublished_ && now - *lastPublished_ < minInterval_) return std::nullopt;
  lastPublished_ = now;
  BuildProgressUpdate u;
  u.stage = stage;
  u.stageIndex = static_cast<std::size_t>(it - stages_.begin());
  u.done = done;
  u.total = total;
  u.elapsedSeconds = secondsBetween(started_, now);
  // The items left at the stage's rate since it was first reported; none
  // while nothing has been done since then (a rate of 0 says nothing).
  const double stageSeconds = secondsBetween(it->start, now);
  if (total > done && done > it->startDone && stageSeconds > 0.0) {
    const double rate = static_cast<double>(done - it->startDone) / stageSeconds;
    u.stageSecondsLeft = static_cast<double>(total - done) / rate;
  }
  if (!plan_.empty()) {
    u.buildFraction = buildFraction_;
    for (const render::PlannedStage& s : plan_.stages) u.stages.push_back(s.name);
    u.buildSecondsLeft = buildSecondsLeft(static_cast<std::size_t>(it - stages_.begin()), now);
  }
  return u;
}

double BuildProgressTracker::buildSecondsLeft(std::size_t current, Clock::time_point now) const {
  auto kind = [](std::string_view name) { return name.substr(0, name.find(' ')); };
  // Seconds and planned work done, per kind and in all, over the reported
  // stages of the plan: a stage's seconds run to the next one's start.
  struct Rate {
    double seconds = 0.0, work = 0.0;
  };
  std::vector<std::pair<std::string_view, Rate>> kinds;
  Rate all;
  for (std::size_t i = 0; i < stages_.size(); ++i) {
    const Stage& s = stages_[i];
    if (!s.planned) continue;
    const Clock::time_point end = i + 1 < stages_.size() ? stages_[i + 1].start : now;
    const double seconds = std::max(0.0, secondsBetween(s.start, end));
    // A stage that another followed is done, whatever it last said.
    const double work = plan_.stages[*s.planned].work * (i == current ? s.fraction : 1.0);
    auto k = std::find_if(kinds.begin(), kinds.end(), [&](const auto& e) { return e.first == kind(s.name); });
    if (k == kinds.end()) k = kinds.insert(kinds.end(), {kind(s.name), Rate{}});
    k->second.seconds += seconds;
    k->second.work += work;
    all.seconds += seconds;
    all.work += work;
  }
  if (all.work < planWork_ / 50.0 || all.seconds < 0.5) return 0.0;
  auto secondsPerWork = [&](std::string_view name) {
    const auto k = std::find_if(kinds.begin(), kinds.end(), [&](const auto& e) { return e.first == kind(name); });
    return k != kinds.end() && k->second.work > 0.0 ? k->second.seconds / k->second.work : all.seconds / all.work;
  };
  // The plan's stages after the current one (a stage outside the plan: those
  // after the last planned stage reported) and the current one's rest.
  std::size_t next = 0;
  double left = 0.0;
  const Stage& c = stages_[current];
  if (c.planned) {
    next = *c.planned + 1;
    left += plan_.stages[*c.planned].work * (1.0 - c.fraction) * secondsPerWork(c.name);
  } else {
    for (const Stage& s : stages_)
      if (s.planned) next = std::max(next, *s.planned + 1);
  }
  for (std::size_t j = next; j < plan_.stages.size(); ++j) left += plan_.stages[j].work * secondsPerWork(plan_.stages[j].name);
  return left;
}

std::string publicStageName(std::string_view stage) {
  // Valid UTF-8 with every control character (C0, DEL) as a space.
  std::string text;
  text.reserve(stage.size());
  for (std::size_t i = 0; i < stage.size();) {
    const std::size_t n = utf8SequenceAt(stage, i);
    if (n == 0) {
      text += '?';
      ++i;
      continue;
    }
    const auto c = static_cast<unsigned char>(stage[i]);
    if (n == 1 && (c < 0x20 || c == 0x7F)) {
      text += ' ';
    } else {
      text.append(stage.substr(i, n));
    }
    i += n;
  }
  // Words, path-like ones cut to their last part, one space apart.
  std::string out;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = std::min(text.find(' ', at), text.size());
    std::string word = text.substr(at, end - at);
    at = end + 1;
    if (word.find_first_of("/\\") != std::string::npos) word = lastPathPart(std::move(word));
    if (word.empty()) continue;
    if (!out.empty()) out += ' ';
    out += word;
  }
  return utf8Prefix(out, kMaxStageBytes);
}

}  // namespace haarcast::net
