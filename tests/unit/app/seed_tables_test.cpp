// seed_tables: the paper's Tables 1–4 as transcribed (checked here against a
// second transcription, digit for digit), and the comparison eval writes:
// one entry per (material, level) measured, a row per seed environment with
// ours beside the paper's, the means, a sentence on why they differ, and
// report.md's tables with the paper's column.
#include "seed_tables.h"

#include <string>

#include <gtest/gtest.h>

namespace haarcast::app {
namespace {

// The seed's Tables 1–4, read again from the paper: Galileo, Grace, RNL,
// St. Petersburg, Uffizi.
struct Expected {
  int number;
  const char* material;
  int level;
  double psnr[5];
};
constexpr Expected kPaper[] = {
    {1, "alum-bronze", 6, {110.82, 110.92, 111.54, 110.76, 111.02}},
    {2, "alum-bronze", 5, {111.17, 111.81, 112.56, 111.29, 111.62}},
    {3, "blue-metallic-paint", 6, {104.28, 104.64, 104.97, 104.66, 104.73}},
    {4, "blue-metallic-paint", 5, {105.49, 106.11, 106.20, 105.55, 105.49}},
};

TEST(SeedTables, TranscribedFromThePaper) {
  ASSERT_EQ(kSeedTables.size(), 4u);
  for (std::size_t t = 0; t < 4; ++t) {
    EXPECT_EQ(kSeedTables[t].number, kPaper[t].number);
    EXPECT_STREQ(kSeedTables[t].material, kPaper[t].material);
    EXPECT_EQ(kSeedTables[t].level, kPaper[t].level);
    for (std::size_t e = 0; e < 5; ++e) EXPECT_EQ(kSeedTables[t].psnr[e], kPaper[t].psnr[e]) << "table " << t + 1;
  }
  const char* columns[] = {"Galileo", "Grace", "RNL", "St. Petersburg", "Uffizi"};
  for (std::size_t e = 0; e < 5; ++e) EXPECT_STREQ(kSeedEnvironments[e].seedName, columns[e]);
  // The two probes that are the seed's own scenes.
  EXPECT_STREQ(kSeedEnvironments[1].probe, "grace");
  EXPECT_TRUE(kSeedEnvironments[1].sameScene);
  EXPECT_STREQ(kSeedEnvironments[4].probe, "uffizi");
  EXPECT_TRUE(kSeedEnvironments[4].sameScene);
}

// report["tables"] as eval writes it, for levels 5 and 6, both materials and
// the five probes: refined 170 + e, faithful 30 + e (+ 5 at level 6).
nlohmann::json measuredTables() {
  nlohmann::json tables;
  const char* probes[] = {"grace", "uffizi", "ennis", "pisa", "wells"};
  for (int level : {5, 6})
    for (const char* material : {"alum-bronze", "blue-metallic-paint"})
      for (int e = 0; e < 5; ++e)
        tables["level" + std::to_string(level)][material][probes[e]] = {
            {"refined", 170.0 + e}, {"faithful", 30.0 + e + (level == 6 ? 5.0 : 0.0)}};
  return tables;
}

nlohmann::json config() {
  return {{"models", {"sphere", "easter"}}, {"rotations_per_model", 1}, {"frame", 24},
          {"machine", {{"cpu_model", "Test CPU"}, {"cores", 2}}}};
}

TEST(SeedTables, ComparisonHasEveryTableAtBothLevels) {
  const nlohmann::json c = seedTableComparison(measuredTables(), config());
  ASSERT_EQ(c.size(), 4u);
  for (std::size_t t = 0; t < 4; ++t) {
    SCOPED_TRACE("table " + std::to_string(t + 1));
    const auto& entry = c[t];
    EXPECT_EQ(entry["table"], kPaper[t].number);
    EXPECT_EQ(entry["material"], kPaper[t].material);
    EXPECT_EQ(entry["level"], kPaper[t].level);
    ASSERT_EQ(entry["rows"].size(), 5u);
    double paperSum = 0.0;
    for (std::size_t e = 0; e < 5; ++e) {
      const auto& row = entry["rows"][e];
      EXPECT_EQ(row["paper"].get<double>(), kPaper[t].psnr[e]);
      paperSum += kPaper[t].psnr[e];
    }
    // Grace is the second column and the first probe: refined 170, faithful 30 (+5).
    EXPECT_EQ(entry["rows"][1]["probe"], "grace");
    EXPECT_EQ(entry["rows"][1]["refined"].get<double>(), 170.0);
    EXPECT_EQ(entry["rows"][1]["faithful"].get<double>(), kPaper[t].level == 6 ? 35.0 : 30.0);
    EXPECT_NEAR(entry["mean"]["refined"].get<double>(), 172.0, 1e-12);
    EXPECT_NEAR(entry["mean"]["paper"].get<double>(), paperSum / 5.0, 1e-12);
    // Why: the method's gap, the conditions, and the level's move beside the seed's.
    const std::string why = entry["why"];
    EXPECT_NE(why.find("exact up to float rounding"), std::string::npos) << why;
    EXPECT_NE(why.find("3 of our 5 probes stand in"), std::string::npos) << why;
    EXPECT_NE(why.find("2 render(s) (2 model(s) × 1 rotation(s), 24² pixels)"), std::string::npos) << why;
    EXPECT_NE(why.find("Test CPU, 2 cores"), std::string::npos) << why;
    EXPECT_NE(why.find("From level 5 to 6 `faithful` moves +5.00 dB"), std::string::npos) << why;
  }
}

TEST(SeedTables, OnlyTheMeasuredTablesAndProbes) {
  // One level, one probe that stands in for none of the seed's.
  nlohmann::json tables;
  tables["level5"]["blue-metallic-paint"]["builtin-sky"] = {{"refined", 160.0}, {"faithful", 40.0}};
  const nlohmann::json c = seedTableComparison(tables, config());
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c[0]["table"], 4);
  ASSERT_EQ(c[0]["rows"].size(), 6u);  // the seed's five, unmeasured, and the sky
  EXPECT_FALSE(c[0]["rows"][0].contains("refined"));
  EXPECT_TRUE(c[0]["rows"][5]["seed_environment"].is_null());
  EXPECT_TRUE(c[0]["rows"][5]["paper"].is_null());
  EXPECT_EQ(c[0]["mean"]["faithful"].get<double>(), 40.0);
  EXPECT_EQ(c[0]["why"].get<std::string>().find("From level"), std::string::npos);  // no level 6 to compare
}

TEST(SeedTables, MarkdownShowsThePapersColumn) {
  const nlohmann::json c = seedTableComparison(measuredTables(), config());
  const std::string md = seedTablesMarkdown(c, config(), nullptr);
  EXPECT_NE(md.find("### Table 1: alum-bronze, level 6 (64×64 maps)"), std::string::npos);
  EXPECT_NE(md.find("### Table 2: alum-bronze, level 5 (32×32 maps)"), std::string::npos);
  EXPECT_NE(md.find("### Table 3: blue-metallic-paint, level 6"), std::string::npos);
  EXPECT_NE(md.find("### Table 4: blue-metallic-paint, level 5"), std::string::npos);
  EXPECT_NE(md.find("| seed's environment | our probe | ours: refined | ours: faithful | paper |"), std::string::npos);
  EXPECT_NE(md.find("| Grace | grace* | 170.00 | 35.00 | 110.92 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| St. Petersburg | wells | 174.00 | 34.00 | 105.55 |"), std::string::npos) << md;
  std::size_t whys = 0;
  for (auto at = md.find("**Why ours differ.**"); at != std::string::npos; at = md.find("**Why ours differ.**", at + 1)) ++whys;
  EXPECT_EQ(whys, 4u);
  EXPECT_EQ(md.find("!["), std::string::npos);  // no figures drawn, none linked
  const nlohmann::json figures = {{"level6", {{"alum-bronze", "mse_level6_alum-bronze.png"}}}};
  EXPECT_NE(seedTablesMarkdown(c, config(), figures).find("](mse_level6_alum-bronze.png)"), std::string::npos);
}

}  // namespace
}  // namespace haarcast::app
