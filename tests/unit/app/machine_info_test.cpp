// machine_info: the CPU model read from /proc/cpuinfo's layout, and the
// words figures and reports use for the machine.
#include "machine_info.h"

#include <gtest/gtest.h>

namespace haarcast::app {
namespace {

TEST(MachineInfo, CpuinfoValue) {
  const std::string text =
      "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC 7B13 64-Core Processor  \n"
      "processor\t: 1\nmodel name\t: AMD EPYC 7B13 64-Core Processor\n";
  EXPECT_EQ(cpuinfoValue(text, "model name"), "AMD EPYC 7B13 64-Core Processor");
  EXPECT_EQ(cpuinfoValue(text, "vendor_id"), "AuthenticAMD");
  EXPECT_EQ(cpuinfoValue(text, "Hardware"), "");
  EXPECT_EQ(cpuinfoValue("", "model name"), "");
}

TEST(MachineInfo, Described) {
  EXPECT_EQ(describeMachine({{"cpu_model", "AMD EPYC"}, {"cores", 2}}), "AMD EPYC, 2 cores");
  EXPECT_EQ(describeMachine({{"cpu_model", "Cortex-A72"}, {"cores", 1}}), "Cortex-A72, 1 core");
  EXPECT_EQ(describeMachine(nlohmann::json::object()), "unknown CPU");
}

TEST(MachineInfo, ThisMachine) {
  const MachineInfo m = machineInfo();
  EXPECT_FALSE(m.cpuModel.empty());
  EXPECT_GE(m.cores, 1u);
  const nlohmann::json j = toJson(m);
  EXPECT_EQ(j["cpu_model"], m.cpuModel);
  EXPECT_EQ(j["cores"], m.cores);
  EXPECT_TRUE(j.contains("load_average_at_start"));
}

}  // namespace
}  // namespace haarcast::app
