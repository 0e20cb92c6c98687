// `haarcast loadtest`'s progress on stderr: on a terminal one line redrawn
// twice a second ("run k of N: …, 12 s in, about 3 min left"), otherwise a
// line per run and one every 10 s. Session messages go through message() so
// that the progress line is not drawn over them.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace haarcast::app {

class LoadtestProgress {
 public:
  explicit LoadtestProgress(std::size_t runs);
  ~LoadtestProgress();
  LoadtestProgress(const LoadtestProgress&) = delete;
  LoadtestProgress& operator=(const LoadtestProgress&) = delete;

  // Run k (from 0) of the total starts; `seconds` is its measured length.
  void startRun(std::size_t k, std::string label, double seconds);
  void endRun();
  // A line of its own (thread-safe: sessions call it from the I/O thread).
  void message(const std::string& text);

 private:
  using Clock = std::chrono::steady_clock;
  std::string left() const;
  void loop();
  static void print(const std::string& s);

  std::size_t runs_;
  bool terminal_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread thread_;
  bool stop_ = false;
  std::size_t k_ = 0;
  std::string label_;
  double seconds_ = 0.0;
  Clock::time_point runStart_;
  std::vector<double> done_;  // wall seconds of the finished runs
};

}  // namespace haarcast::app
