#include "loadtest_progress.h"

#include <algorithm>
#include <cstdio>

#include "progress.h"

namespace haarcast::app {

LoadtestProgress::LoadtestProgress(std::size_t runs) : runs_(runs), terminal_(stderrIsTerminal()) {}

LoadtestProgress::~LoadtestProgress() { endRun(); }

void LoadtestProgress::startRun(std::size_t k, std::string label, double seconds) {
  std::lock_guard lock(mutex_);
  k_ = k, label_ = std::move(label), seconds_ = seconds, runStart_ = Clock::now(), stop_ = false;
  if (!terminal_) print("[loadtest] run " + std::to_string(k + 1) + " of " + std::to_string(runs_) + ": " + label_ + ", " + left() + "\n");
  thread_ = std::thread([this] { loop(); });
}

void LoadtestProgress::endRun() {
  {
    std::lock_guard lock(mutex_);
    if (!thread_.joinable()) return;
    stop_ = true;
    done_.push_back(std::chrono::duration<double>(Clock::now() - runStart_).count());
  }
  wake_.notify_all();
  thread_.join();
  std::lock_guard lock(mutex_);
  if (terminal_) print("\r\x1b[K");
}

void LoadtestProgress::message(const std::string& text) {
  std::lock_guard lock(mutex_);
  print(std::string(terminal_ ? "\r\x1b[K" : "") + "[loadtest] " + text + "\n");
}

// "about 3 min 10 s left": this run's remaining time plus the mean of the
// finished runs (or the run length itself before any finished) per run to go.
std::string LoadtestProgress::left() const {
  const double elapsed = std::chrono::duration<double>(Clock::now() - runStart_).count();
  double perRun = seconds_;
  if (!done_.empty()) {
    perRun = 0.0;
    for (double d : done_) perRun += d / static_cast<double>(done_.size());
  }
  const double rest = std::max(0.0, perRun - elapsed) + perRun * static_cast<double>(runs_ - k_ - 1);
  return "about " + formatDuration(rest) + " left";
}

void LoadtestProgress::loop() {
  std::unique_lock lock(mutex_);
  auto lastLine = Clock::now();
  while (!wake_.wait_for(lock, std::chrono::milliseconds(500), [this] { return stop_; })) {
    const double elapsed = std::chrono::duration<double>(Clock::now() - runStart_).count();
    const std::string line = "[loadtest] run " + std::to_string(k_ + 1) + " of " + std::to_string(runs_) + ": " +
                             label_ + ", " + formatDuration(elapsed) + " in, " + left();
    if (terminal_) {
      print("\r" + line + "\x1b[K");
    } else if (Clock::now() - lastLine >= std::chrono::seconds(10)) {
      print(line + "\n");
      lastLine = Clock::now();
    }
  }
}

void LoadtestProgress::print(const std::string& s) {
  std::fputs(s.c_str(), stderr);
  std::fflush(stderr);
}

}  // namespace haarcast::app
