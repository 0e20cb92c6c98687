#include "machine_info.h"

#include <fstream>
#include <sstream>
#include <thread>

namespace haarcast::app {
namespace {

std::string trimmed(const std::string& s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

std::string fileText(const char* path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

std::string cpuinfoValue(const std::string& text, const std::string& key) {
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const auto colon = line.find(':');
    if (colon != std::string::npos && trimmed(line.substr(0, colon)) == key) return trimmed(line.substr(colon + 1));
  }
  return {};
}

MachineInfo machineInfo() {
  MachineInfo m;
  const std::string cpuinfo = fileText("/proc/cpuinfo");
  // x86 says "model name"; some ARM kernels only "Hardware", POWER and MIPS "cpu model".
  for (const char* key : {"model name", "Hardware", "cpu model"}) {
    m.cpuModel = cpuinfoValue(cpuinfo, key);
    if (!m.cpuModel.empty()) break;
  }
  if (m.cpuModel.empty()) m.cpuModel = "unknown CPU";
  m.cores = std::thread::hardware_concurrency();
  std::istringstream load(fileText("/proc/loadavg"));
  std::string a, b, c;
  m.loadAverage = load >> a >> b >> c ? a + " " + b + " " + c : "unknown";
  return m;
}

nlohmann::json toJson(const MachineInfo& m) {
  return {{"cpu_model", m.cpuModel}, {"cores", m.cores}, {"load_average_at_start", m.loadAverage}};
}

std::string describeMachine(const nlohmann::json& machine) {
  const std::string cpu = machine.value("cpu_model", std::string("unknown CPU"));
  const unsigned cores = machine.value("cores", 0u);
  return cores ? cpu + ", " + std::to_string(cores) + (cores == 1 ? " core" : " cores") : cpu;
}

}  // namespace haarcast::app
