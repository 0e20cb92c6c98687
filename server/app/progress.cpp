#include "progress.h"

#include <chrono>
#include <cstdlib>
#include <cstring>

#include <unistd.h>

namespace haarcast::app {

bool stderrIsTerminal() {
  // A dumb terminal cannot erase to the end of the line: it gets log lines.
  const char* term = std::getenv("TERM");
  return isatty(fileno(stderr)) != 0 && !(term && std::strcmp(term, "dumb") == 0);
}

ProgressOptions stderrProgressOptions(std::string prefix, bool allowRedraw) {
  ProgressOptions o;
  o.terminal = allowRedraw && stderrIsTerminal();
  o.prefix = std::move(prefix);
  return o;
}

ProgressReporter::Sink stderrSink() {
  return [](const std::string& text) {
    std::fputs(text.c_str(), stderr);
    std::fflush(stderr);
  };
}

ProgressReporter::Clock steadyClock() {
  return [] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  };
}

}  // namespace haarcast::app
