// The process figures in /metrics agree with what the kernel says of this
// process, measured independently (/proc/self/status and the CPU clock).
#include <ctime>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "haarcast/net/metrics.h"

namespace haarcast::net {
namespace {

double sample(const std::string& text, const std::string& name) {
  const std::regex line("(^|\n)" + name + " ([0-9.eE+-]+)\n");
  std::smatch m;
  if (!std::regex_search(text, m, line)) return -1.0;
  return std::stod(m[2].str());
}

double vmRssBytes() {
  std::ifstream status("/proc/self/status");
  for (std::string l; std::getline(status, l);) {
    if (l.rfind("VmRSS:", 0) == 0) return 1024.0 * std::stod(l.substr(6));
  }
  return -1.0;
}

double processCpuClock() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

TEST(Metrics, ProcessResidentMemoryIsThisProcesssRss) {
  Metrics metrics;
  // Touch 64 MiB so the figure is well above noise and must have moved.
  std::vector<char> block(64u << 20, 1);
  const double rss = sample(metrics.prometheusText(), "process_resident_memory_bytes");
  const double expected = vmRssBytes();
  ASSERT_GT(expected, 0.0);
  EXPECT_GT(rss, 64.0 * (1 << 20)) << "the 64 MiB just touched are resident";
  EXPECT_NEAR(rss, expected, 0.05 * expected) << "VmRSS " << expected;
  EXPECT_EQ(block[block.size() / 2], 1);
}

TEST(Metrics, ProcessCpuSecondsFollowTheProcessClock) {
  Metrics metrics;
  const double before = sample(metrics.prometheusText(), "process_cpu_seconds_total");
  const double clock0 = processCpuClock();
  volatile double sink = 0.0;
  while (processCpuClock() - clock0 < 0.3) sink = sink + 1.0;
  const double after = sample(metrics.prometheusText(), "process_cpu_seconds_total");
  const double burnt = processCpuClock() - clock0;
  ASSERT_GE(before, 0.0);
  EXPECT_NEAR(after - before, burnt, 0.05 + 0.1 * burnt);
}

}  // namespace
}  // namespace haarcast::net
