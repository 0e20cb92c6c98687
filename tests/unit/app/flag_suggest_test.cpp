// "Did you mean" for misspelt flags and commands (client/cli/include/haarcast/client/flag_suggest.h),
// against a CLI::App built here: typos of one or two edits are matched, a
// swap of neighbours counts as one, values that start with '-' are not
// flags, and a word far from every flag gets no guess.
#include "haarcast/client/flag_suggest.h"

#include <gtest/gtest.h>

namespace haarcast::cli {
namespace {

TEST(FlagSuggest, EditDistanceCountsASwapOfNeighboursAsOne) {
  EXPECT_EQ(editDistance("width", "width"), 0u);
  EXPECT_EQ(editDistance("widht", "width"), 1u);
  EXPECT_EQ(editDistance("heigth", "height"), 1u);
  EXPECT_EQ(editDistance("rendr", "render"), 1u);
  EXPECT_EQ(editDistance("", "abc"), 3u);
  EXPECT_EQ(editDistance("level", "levels"), 1u);
}

TEST(FlagSuggest, NamesTheFlagMeantAndOnlyUnknownFlags) {
  CLI::App app{"test"};
  auto* render = app.add_subcommand("render", "Render a frame");
  int width = 0, height = 0, k = 0;
  std::string rotate, out;
  render->add_option("--width", width);
  render->add_option("--height", height);
  render->add_option("--rotate", rotate);
  render->add_option("-k,--coefficients", k);
  render->add_option("--out", out);

  EXPECT_EQ(unknownFlags(*render, {"--widht", "64"}), std::vector<std::string>{"unknown flag --widht; did you mean --width?"});
  EXPECT_EQ(unknownFlags(*render, {"--heigth=32"}), std::vector<std::string>{"unknown flag --heigth; did you mean --height?"});
  EXPECT_EQ(unknownFlags(*render, {"--coefficient", "9"}),
            std::vector<std::string>{"unknown flag --coefficient; did you mean --coefficients?"});
  // Known flags, values that look like flags, and anything after "--" are left alone.
  EXPECT_TRUE(unknownFlags(*render, {"--width", "64", "-k", "9", "--rotate", "-30,0,0", "-1.5", "--", "--nope"}).empty());
  // Too far from every flag: named, with no guess; a one-letter flag gets none either.
  EXPECT_EQ(unknownFlags(*render, {"--backdrop"}), std::vector<std::string>{"unknown flag --backdrop"});
  EXPECT_EQ(unknownFlags(*render, {"-x"}), std::vector<std::string>{"unknown flag -x"});
  // Each unknown flag once, in order.
  EXPECT_EQ(unknownFlags(*render, {"--widht", "1", "--ot", "x.exr"}),
            (std::vector<std::string>{"unknown flag --widht; did you mean --width?", "unknown flag --ot; did you mean --out?"}));
}

TEST(FlagSuggest, TheCommandListNamesEachCommandWithItsDescription) {
  CLI::App app{"test"};
  app.add_subcommand("render", "Render a frame");
  app.add_subcommand("bench-frame", "Time frames");
  EXPECT_EQ(commandList(app), "  render       Render a frame\n  bench-frame  Time frames\n");
  EXPECT_EQ(nearestName("rendr", {"render", "bench-frame"}), std::optional<std::string>("render"));
  EXPECT_EQ(nearestName("serve", {"render", "bench-frame"}), std::nullopt);
}

}  // namespace
}  // namespace haarcast::cli
