// The machine a measurement ran on, as reports and figures name it: timings
// and frame rates mean little without the CPU, how many cores the run could
// use and how busy the machine already was.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace haarcast::app {

struct MachineInfo {
  std::string cpuModel;     // /proc/cpuinfo's first "model name" (or "Hardware", "cpu model"); "unknown CPU"
  unsigned cores = 0;       // std::thread::hardware_concurrency(): the renderer's default thread count
  std::string loadAverage;  // /proc/loadavg's 1, 5 and 15 minute averages; "unknown"
};

MachineInfo machineInfo();

// {"cpu_model", "cores", "load_average_at_start"}: the keys report.json files use.
nlohmann::json toJson(const MachineInfo& machine);

// "AMD EPYC, 2 cores": what a figure's title and a report's prose say.
std::string describeMachine(const nlohmann::json& machine);

// The first value of `key` in text laid out as /proc/cpuinfo is
// ("key<tabs>: value" lines), trimmed; empty when absent. Pure, for tests.
std::string cpuinfoValue(const std::string& text, const std::string& key);

}  // namespace haarcast::app
