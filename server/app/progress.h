// Progress of the command line's long stages (slice tables, visibility, Monte
// Carlo, the evaluation's renders): a percentage and the time left, redrawn
// in place on a terminal, periodic lines in a log. A stage that ends within
// a couple of seconds prints nothing.
//
//   terminal   "\r[visibility bunny]  42% (15000/35947), 1 min 12 s left\x1b[K"  (redrawn)
//              "\r[visibility bunny] 100% (35947/35947) in 1 min 35 s\x1b[K\n"    (at the end)
//   log        "[visibility bunny]  40% (14379/35947), 1 min 20 s left\n"          (each 10 % more,
//              "[visibility bunny] 100% (35947/35947) in 1 min 35 s\n"             or after 10 s)
//
// The logic is here, header-only, with the clock and the output injected so
// that tests can drive it; stderrProgress() (progress.cpp) binds it to the
// steady clock and stderr.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "haarcast/client/build_progress.h"  // client: formatDuration

namespace haarcast::app {

// What long steps report: done of total items of a named stage. The same
// shape as render::RenderProgress, so one callback serves both.
using StageProgress = std::function<void(const std::string& stage, std::size_t done, std::size_t total)>;

struct ProgressOptions {
  bool terminal = false;        // redraw one line in place, else print lines
  double quietSeconds = 2.0;    // a stage that ends sooner prints nothing
  double redrawSeconds = 0.1;   // terminal: redraw at most this often
  int logPercentStep = 10;      // log: a line when this many more percent are done than at the last,
  double logSeconds = 10.0;     //      or when this long has passed since it
  std::string prefix;           // before every line, e.g. "[serve] "
};

// "0.4 s", "12 s", "3 min 05 s", "2 h 07 min": the client's formatter, one
// definition for every progress line of the project.
using client::formatDuration;

// Samples per pixel a Monte Carlo render will have when it stops: its
// half-image difference falls as 1/√samples, so reaching `tolerance` from
// `error` at `samples` takes samples·(error/tolerance)², capped at
// maxSamples (and never fewer than taken). tolerance ≤ 0 runs to maxSamples.
inline std::size_t estimatedSamplesToConverge(std::size_t samples, double error, double tolerance,
                                              std::size_t maxSamples) {
  if (!(tolerance > 0.0) || !std::isfinite(error)) return std::max(samples, maxSamples);
  const double ratio = error / tolerance;
  const double needed = static_cast<double>(samples) * ratio * ratio;
  const double capped = std::min(needed, static_cast<double>(maxSamples));
  return std::max(samples, static_cast<std::size_t>(std::ceil(capped)));
}

class ProgressReporter {
 public:
  using Clock = std::function<double()>;                  // seconds, monotonic
  using Sink = std::function<void(const std::string&)>;   // written as is (carries its own \r and \n)

  ProgressReporter(ProgressOptions options, Sink sink, Clock clock)
      : o_(std::move(options)), sink_(std::move(sink)), clock_(std::move(clock)) {}
  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;

  // done of total items of `stage`. A stage starts the first time its name
  // is seen and ends when done ≥ total; stages may nest (an outer loop whose
  // items run inner stages): each keeps its own start and rate. `detail`,
  // when given, replaces "(done/total)" in the line.
  void update(const std::string& stage, std::size_t done, std::size_t total, const std::string& detail = {}) {
    const double now = clock_();
    Stage& s = find(stage, now, done);
    s.done = done;
    s.total = total;
    s.detail = detail;
    if (total == 0 || done >= total) {
      end(stage, now);
      return;
    }
    if (now - s.start < o_.quietSeconds) return;
    const std::string text = line(stage, s, now, false);
    if (o_.terminal) {
      if (s.shown && drawn_ == stage && now - lastDraw_ < o_.redrawSeconds) return;
      draw(stage, text, now);
    } else {
      // Steps count from the last line, not from round percentages: a line
      // printed after a silence at 19 % is not followed by another at 20 %.
      const int pct = percent(s);
      if (s.shown && pct - s.loggedPercent < o_.logPercentStep && now - s.lastLine < o_.logSeconds) return;
      sink_(o_.prefix + text + "\n");
      s.loggedPercent = pct;
      s.lastLine = now;
    }
    s.shown = true;
  }

  // Ends a stage that stops before its total (a Monte Carlo render that
  // converged early): its last line says 100 % with `detail`.
  void finish(const std::string& stage, const std::string& detail = {}) {
    const auto it = std::find_if(stages_.begin(), stages_.end(), [&](const auto& p) { return p.first == stage; });
    if (it == stages_.end()) return;
    it->second.done = it->second.total = std::max(it->second.done, std::size_t{1});
    if (!detail.empty()) it->second.detail = detail;
    end(stage, clock_());
  }

  // A line of its own (a result, a warning) that the progress line must not
  // garble: on a terminal the progress line is cleared, the message printed
  // and the progress line drawn again below it.
  void message(const std::string& text) {
    if (o_.terminal && !drawn_.empty()) {
      sink_("\r\x1b[K" + o_.prefix + text + "\n" + drawnText_);
    } else {
      sink_(o_.prefix + text + "\n");
    }
  }

  // The callback the render library and the reports take.
  StageProgress callback() {
    return [this](const std::string& stage, std::size_t done, std::size_t total) { update(stage, done, total); };
  }

 private:
  struct Stage {
    double start = 0.0;
    std::size_t startDone = 0;  // done when first seen: the rate counts from there
    std::size_t done = 0, total = 0;
    std::string detail;
    bool shown = false;
    int loggedPercent = 0;
    double lastLine = 0.0;
  };

  Stage& find(const std::string& stage, double now, std::size_t done) {
    for (auto& [name, s] : stages_)
      if (name == stage) return s;
    Stage s;
    s.start = now;
    s.startDone = done;
    stages_.emplace_back(stage, s);
    return stages_.back().second;
  }

  static int percent(const Stage& s) {
    if (s.total == 0 || s.done >= s.total) return 100;
    // Never "100%" before the end.
    return std::min(99, static_cast<int>(100.0 * static_cast<double>(s.done) / static_cast<double>(s.total)));
  }

  std::string line(const std::string& stage, const Stage& s, double now, bool finished) const {
    char pct[16];
    std::snprintf(pct, sizeof pct, "%3d%%", percent(s));
    std::string out = "[" + stage + "] " + pct + " ";
    out += s.detail.empty() ? "(" + std::to_string(s.done) + "/" + std::to_string(s.total) + ")" : s.detail;
    const double elapsed = now - s.start;
    if (finished) return out + " in " + formatDuration(elapsed);
    // The rate since the stage was first seen; none yet, no estimate.
    if (s.done > s.startDone && elapsed > 0.0) {
      const double rate = static_cast<double>(s.done - s.startDone) / elapsed;
      out += ", " + formatDuration(static_cast<double>(s.total - s.done) / rate) + " left";
    }
    return out;
  }

  void draw(const std::string& stage, const std::string& text, double now) {
    drawnText_ = "\r" + o_.prefix + text + "\x1b[K";
    sink_(drawnText_);
    drawn_ = stage;
    lastDraw_ = now;
  }

  void end(const std::string& stage, double now) {
    const auto it = std::find_if(stages_.begin(), stages_.end(), [&](const auto& p) { return p.first == stage; });
    if (it == stages_.end()) return;
    if (it->second.shown) {
      const std::string text = o_.prefix + line(stage, it->second, now, true);
      sink_(o_.terminal ? "\r" + text + "\x1b[K\n" : text + "\n");
      if (o_.terminal) {
        // An outer stage's line, if any, is drawn again by its next update.
        drawn_.clear();
        drawnText_.clear();
      }
    }
    if (drawn_ == stage) {
      drawn_.clear();
      drawnText_.clear();
    }
    stages_.erase(it);
  }

  ProgressOptions o_;
  Sink sink_;
  Clock clock_;
  std::vector<std::pair<std::string, Stage>> stages_;  // open stages, in the order they started
  std::string drawn_, drawnText_;                      // terminal: the stage on the line and its text
  double lastDraw_ = 0.0;
};

// A Monte Carlo render's progress(samples, half-image difference) as a stage
// of `reporter`: the percentage of the samples it will take to converge
// (estimatedSamplesToConverge), so the time left is an estimate that firms
// up as the error settles. Call reporter.finish(stage, …) after the render:
// it may stop short of the estimate.
inline std::function<void(int, double)> monteCarloProgress(ProgressReporter& reporter, std::string stage,
                                                           double tolerance, int maxSamples) {
  return [&reporter, stage = std::move(stage), tolerance, maxSamples](int samples, double error) {
    const auto done = static_cast<std::size_t>(std::max(samples, 0));
    const std::size_t total =
        estimatedSamplesToConverge(done, error, tolerance, static_cast<std::size_t>(std::max(maxSamples, 1)));
    char detail[128];
    std::snprintf(detail, sizeof detail, "%d samples/pixel, half-image difference %.4f (goal %.4f)", samples, error,
                  tolerance);
    reporter.update(stage, done, total, detail);
  };
}

// ---- bound to the process (progress.cpp) ------------------------------------

// stderr is a terminal that can redraw a line (not TERM=dumb).
bool stderrIsTerminal();
// Options for stderr: redrawn on a terminal unless allowRedraw is false (a
// server whose other threads log lines in between).
ProgressOptions stderrProgressOptions(std::string prefix = {}, bool allowRedraw = true);
ProgressReporter::Sink stderrSink();
ProgressReporter::Clock steadyClock();

// The reporter the commands use: stderr, the steady clock.
class StderrProgress : public ProgressReporter {
 public:
  explicit StderrProgress(std::string prefix = {}, bool allowRedraw = true)
      : ProgressReporter(stderrProgressOptions(std::move(prefix), allowRedraw), stderrSink(), steadyClock()) {}
};

}  // namespace haarcast::app
