// The server's BuildProgress messages on stderr, while the renderer a
// session waits for is built (docs/service.md):
//
//   terminal   "\rbuilding: visibility bunny  42 % (~3.1 s left in this stage)\x1b[K"   (redrawn)
//              "\rbuilding: ready after 12.3 s\x1b[K\n"                                  (at Welcome)
//   otherwise  "building: visibility bunny  40 % (~3.4 s left in this stage)\n"          (a line at each new
//              "building: ready after 12.3 s\n"                                          stage, every 10 %, or 5 s)
//
// The time left is the server's estimate for the current stage alone (its
// rate so far); later stages are not in it, hence "in this stage". A server
// that sends no BuildProgress (an older one, or a cached renderer) shows
// nothing. Output and clock are injected, so tests drive it without a
// terminal.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

#include "haarcast/proto/haarcast.pb.h"

namespace haarcast::client {

// "visibility bunny  42 % (~3.1 s left in this stage)": the stage, the
// percentage when the total is known (100 only when done), the estimate when
// there is one. Control characters in the stage are shown as '?'.
std::string buildProgressText(const v1::BuildProgress& progress);

// "0.4 s", "12 s", "3 min 05 s", "2 h 07 min".
std::string formatDuration(double seconds);

class BuildProgressDisplay {
 public:
  using Sink = std::function<void(const std::string&)>;  // written as is (carries its own \r and \n)

  BuildProgressDisplay(bool terminal, Sink sink) : terminal_(terminal), sink_(std::move(sink)) {}

  // A BuildProgress arrived at `now` (seconds, any monotonic origin).
  void update(const v1::BuildProgress& progress, double now);
  // The renderer is ready (Welcome): the last line says how long the build
  // took, if any progress was shown. Nothing otherwise.
  void ready(double now);
  // Before another line is printed: a redrawn line is ended first.
  void endLine();
  bool lineOpen() const { return lineOpen_; }

 private:
  bool terminal_;
  Sink sink_;
  bool shown_ = false;     // a line of the current build was printed
  bool lineOpen_ = false;  // terminal: the redrawn line has no newline yet
  std::uint32_t lastStage_ = 0;
  int lastPercent_ = -1;
  double lastLineAt_ = 0.0;
  double lastElapsed_ = 0.0, lastAt_ = 0.0;  // the server's elapsed time, and when it came
};

}  // namespace haarcast::client
