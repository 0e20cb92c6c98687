#include "report_figures.h"

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <system_error>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include "app_paths.h"

extern char** environ;

namespace haarcast::app {
namespace {

namespace fs = std::filesystem;

constexpr int kSpawnFailed = -1;

// Runs argv[0] (looked up on PATH) with argv and waits; returns its exit
// status, kSpawnFailed when it could not start, 128 + signal when killed.
// quiet: stdout and stderr to /dev/null; else stdout goes to stderr.
int runProgram(const std::vector<std::string>& argv, bool quiet) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (quiet) {
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  } else {
    posix_spawn_file_actions_adddup2(&actions, STDERR_FILENO, STDOUT_FILENO);
  }
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return kSpawnFailed;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return kSpawnFailed;
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  return WIFSIGNALED(status) ? 128 + WTERMSIG(status) : kSpawnFailed;
}

std::string joined(const std::vector<std::string>& v) {
  std::string out;
  for (const auto& s : v) out += (out.empty() ? "" : ", ") + s;
  return out;
}

}  // namespace

fs::path findPlotScript() {
  return findShipped("tools/plot_report.py", {"../share/haarcast/plot_report.py", "plot_report.py"});
}

std::vector<std::string> pythonCandidates() {
  if (const char* chosen = std::getenv("HAARCAST_PYTHON"); chosen && *chosen) return {chosen};
  return {"python3", "/usr/bin/python3"};
}

FigureRun drawReportFigures(const fs::path& reportJson) {
  FigureRun run;
  const fs::path script = findPlotScript();
  if (script.empty()) {
    run.problem = "tools/plot_report.py was not found beside this haarcast (" + executableDir().string() +
                  ") nor in its source tree";
    return run;
  }
  run.script = script.string();
  const std::vector<std::string> candidates = pythonCandidates();
  bool anyPython = false;
  for (const std::string& python : candidates) {
    const int rc = runProgram({python, "-c", "import matplotlib"}, true);
    if (rc == 0) {
      run.python = python;
      break;
    }
    // 127: a shell-style "not found"; kSpawnFailed: no such program.
    anyPython = anyPython || (rc != kSpawnFailed && rc != 127);
  }
  if (run.python.empty()) {
    run.problem = std::string(anyPython ? "python3 has no matplotlib" : "no python3 found") + " (tried " +
                  joined(candidates) + "). Install it with `apt-get install python3-matplotlib`, then draw them with `python3 " +
                  run.script + " " + reportJson.string() + "`";
    return run;
  }
  const auto t0 = std::chrono::steady_clock::now();
  const int rc = runProgram({run.python, run.script, reportJson.string()}, false);
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (rc == 0) {
    run.status = FigureRun::Status::Drawn;
  } else {
    run.status = FigureRun::Status::Failed;
    run.problem = run.python + " " + run.script + " exited with status " + std::to_string(rc);
  }
  return run;
}

}  // namespace haarcast::app
