// The server `haarcast loadtest` measures: its own `haarcast serve` child on
// loopback, or one already running (--url). Either way it reports the
// server's CPU seconds and resident memory around each run: from /proc for
// the child, from the Prometheus `process_*` metrics of /metrics for a remote
// server (null when it does not export them).
#pragma once

#include <sys/types.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace haarcast::app {

struct ProcessFigures {
  std::optional<double> cpuSeconds;      // user + system, since the process started
  std::optional<std::uint64_t> rssBytes;  // resident now
  std::optional<std::uint64_t> peakRssBytes;  // the most it was resident (VmHWM)
};

// /proc/<pid>/stat fields 14 and 15 (utime, stime, in clock ticks; proc(5))
// and /proc/<pid>/status VmRSS and VmHWM (kB). Pure parsers, so that a test
// can feed them text; each throws std::invalid_argument naming the field it
// could not read.
double parseProcStatCpuSeconds(std::string_view stat, long ticksPerSecond);
std::optional<std::uint64_t> parseProcStatusKb(std::string_view status, std::string_view field);
ProcessFigures procFigures(pid_t pid);

// The standard Prometheus process metrics (process_cpu_seconds_total,
// process_resident_memory_bytes) from a /metrics text; absent ones stay
// empty.
ProcessFigures parseMetricsFigures(std::string_view metricsText);
// GET http://host:port/metrics; empty figures when it cannot be read.
ProcessFigures fetchMetricsFigures(const std::string& host, const std::string& port);

// `/proc/self/exe serve --port 0 --bind 127.0.0.1 --quiet <extra>` as a
// child: waits for its "listening on http://127.0.0.1:PORT/" line and keeps
// the port. The child gets SIGTERM when this object is destroyed, when
// stop() is called, when this process dies (PR_SET_PDEATHSIG) and on Ctrl-C
// (installInterruptHandler), so that it is never left running.
class LocalServer {
 public:
  // Throws std::runtime_error with the child's exit status when it dies or
  // says nothing within startSeconds.
  LocalServer(const std::vector<std::string>& extraArgs, double startSeconds);
  ~LocalServer();
  LocalServer(const LocalServer&) = delete;
  LocalServer& operator=(const LocalServer&) = delete;

  std::uint16_t port() const { return port_; }
  pid_t pid() const { return pid_; }
  ProcessFigures figures() const { return procFigures(pid_); }
  // SIGTERM, then waits (SIGKILL after graceSeconds); the exit status as
  // `$?` would say it (128 + signal when killed). Idempotent.
  int stop(double graceSeconds = 60.0);

 private:
  pid_t pid_ = -1;
  int stdoutFd_ = -1;  // kept open: the child never writes to a closed pipe
  std::uint16_t port_ = 0;
  int exitStatus_ = -1;
};

// SIGINT/SIGTERM to this process: SIGTERM to the running child, then the
// signal's default action. Installed once; harmless without a child.
void installInterruptHandler();

}  // namespace haarcast::app
