// The evaluation's figures are drawn by matplotlib from report.json, by the
// script the project ships (tools/plot_report.py). This finds a python3 that
// has matplotlib and the script, and runs it; without them the report is
// still complete as JSON and Markdown, and the reason says what to install.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace haarcast::app {

struct FigureRun {
  enum class Status {
    Drawn,        // the script ran and exited 0
    Unavailable,  // no python3 with matplotlib, or no script: nothing ran
    Failed,       // the script ran and failed (its own message is on stderr)
  };
  Status status = Status::Unavailable;
  std::string python;  // the interpreter used, when one was found
  std::string script;  // the script, when found
  std::string problem; // why not drawn, in words, naming what to install
  double seconds = 0.0;
};

// Where tools/plot_report.py is: the source tree's copy (a build folder's
// binary), else <prefix>/share/haarcast/ beside an installed one. Empty when
// neither exists.
std::filesystem::path findPlotScript();

// The interpreters tried, in order: $HAARCAST_PYTHON alone when set, else
// python3 on PATH, then Debian's /usr/bin/python3 (python3-matplotlib
// installs there, and a python3 earlier on PATH may be another one).
std::vector<std::string> pythonCandidates();

// Runs the script on reportJson (figures written beside it). The script's
// output goes to stderr, so that stdout stays the report (eval --json).
FigureRun drawReportFigures(const std::filesystem::path& reportJson);

}  // namespace haarcast::app
