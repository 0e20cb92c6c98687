// eval's ranking of the methods (eval_methods.h): ranks with ties, and the
// report.md section from a report.json made here by hand.
#include "eval_methods.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace haarcast::app {
namespace {

TEST(MethodRanking, RanksTheSmallestFirstAndTiesShareARank) {
  EXPECT_EQ(ranksAscending({3.0, 1.0, 3.0, 0.5}), (std::vector<int>{3, 2, 3, 1}));
  EXPECT_EQ(ranksAscending({}), std::vector<int>{});
  EXPECT_EQ(bytesText(1000), "1000 B");
  EXPECT_EQ(bytesText(1536), "1.5 KiB");
  EXPECT_EQ(bytesText(3.0 * 1024 * 1024), "3.0 MiB");
  std::vector<std::string> roles;
  for (const RankedMaterial& m : rankedMaterials()) roles.push_back(m.role);
  EXPECT_EQ(roles, (std::vector<std::string>{"rough", "glossy", "near-mirror"}));
}

nlohmann::json method(double l2, double seconds, double bytes, int truth, int speed, int storage) {
  return {{"psnr", 30.0}, {"relative_l2", l2}, {"brightness", 1.0}, {"frame_seconds", seconds}, {"precompute_seconds", 0.5},
          {"stored_bytes", bytes}, {"rank", {{"truth", truth}, {"speed", speed}, {"storage", storage}}}};
}

TEST(MethodRanking, TheReportShowsTheSummaryAndEachMaterialInTruthOrder) {
  nlohmann::json r;
  r["config"] = {{"probe", "p"}, {"model", "sphere"}, {"frame", 16}, {"level", 4}, {"frames_timed", 2},
                 {"tolerance", 0.05}, {"max_samples", 256}, {"light_coefficients", 256}, {"theta_samples", 16},
                 {"methods", {"fused", "splitsum"}}};
  for (const auto& [spec, role] : {std::pair{"ggx:0.02", "near-mirror"}, std::pair{"ggx:0.3", "rough"}}) {
    auto& m = r["materials"][spec];
    m["role"] = role;
    m["mc"] = {{"samples", 256}, {"half_error", 0.01}};
    m["floor"] = {{"psnr", 50.0}, {"relative_l2", 0.03}, {"brightness", 1.0}};
    m["methods"]["fused"] = method(0.10, 0.100, 2.0 * 1024 * 1024, 1, 2, 2);
    m["methods"]["splitsum"] = method(0.50, 0.004, 1024, 2, 1, 1);
  }
  r["summary"]["fused"] = {{"speed", 2.0}, {"storage", 2.0}, {"truth", 1.0}};
  r["summary"]["splitsum"] = {{"speed", 1.0}, {"storage", 1.0}, {"truth", 2.0}};
  const std::string md = methodRankingMarkdown(r);
  EXPECT_NE(md.find("## Methods ranked: speed, storage, truth"), std::string::npos);
  EXPECT_NE(md.find("| splitsum | 1.0 | 1.0 | 2.0 | 1.0 KiB | 4.0 | 4.0 | 50.0 % | 50.0 % |"), std::string::npos) << md;
  EXPECT_NE(md.find("| fused | 2.0 | 2.0 | 1.0 | 2.0 MiB |"), std::string::npos) << md;
  // The rough material first, and in each table the closest method first.
  const std::size_t rough = md.find("### ggx:0.3 (rough)"), mirror = md.find("### ggx:0.02 (near-mirror)");
  ASSERT_NE(rough, std::string::npos);
  ASSERT_NE(mirror, std::string::npos);
  EXPECT_LT(rough, mirror);
  EXPECT_LT(md.find("| 1 | fused |", rough), md.find("| 2 | splitsum |", rough));
  EXPECT_NE(md.find("Floor 50.00 dB, relative L2 3.00 %"), std::string::npos) << md;
}

}  // namespace
}  // namespace haarcast::app
