// The progress reporter of the command line, driven by a fake clock and a
// string sink: percentages, the time left, both line formats, quiet short stages.
#include "progress.h"

#include <string>

#include <gtest/gtest.h>

namespace haarcast::app {
namespace {

struct Fixture {
  double now = 100.0;  // the clock need not start at 0
  std::string out;
  ProgressOptions options;

  ProgressReporter make() {
    return ProgressReporter(options, [this](const std::string& s) { out += s; }, [this] { return now; });
  }
};

TEST(FormatDuration, PicksUnitsByMagnitude) {
  EXPECT_EQ(formatDuration(0.42), "0.4 s");
  EXPECT_EQ(formatDuration(12.2), "12 s");
  EXPECT_EQ(formatDuration(65.0), "1 min 05 s");
  EXPECT_EQ(formatDuration(3599.0), "59 min 59 s");
  EXPECT_EQ(formatDuration(7620.0), "2 h 07 min");
  EXPECT_EQ(formatDuration(-3.0), "0.0 s");
}

TEST(Progress, StageEndingUnderTheThresholdPrintsNothing) {
  for (bool terminal : {false, true}) {
    Fixture f;
    f.options.terminal = terminal;
    ProgressReporter p = f.make();
    for (std::size_t i = 0; i <= 16; ++i) {
      p.update("slices bunny", i, 16);
      f.now += 0.1;  // 1.7 s in all
    }
    EXPECT_EQ(f.out, "") << "terminal " << terminal;
  }
}

TEST(Progress, PercentageAndTimeLeftFromTheClock) {
  Fixture f;
  f.options.terminal = true;
  ProgressReporter p = f.make();
  p.update("visibility bunny", 0, 100);
  f.now += 10.0;
  p.update("visibility bunny", 25, 100);
  // 25 items in 10 s: 2.5 per second, 75 left → 30 s.
  EXPECT_EQ(f.out, "\r[visibility bunny]  25% (25/100), 30 s left\x1b[K");
}

TEST(Progress, RateCountsFromWhenTheStageWasFirstSeen) {
  Fixture f;
  f.options.terminal = true;
  ProgressReporter p = f.make();
  p.update("visibility bunny", 40, 1000);  // first seen with 40 done: no rate yet
  f.now += 3.0;
  p.update("visibility bunny", 40, 1000);
  EXPECT_EQ(f.out, "\r[visibility bunny]   4% (40/1000)\x1b[K") << "no estimate without a rate";
  f.out.clear();
  f.now += 1.0;
  p.update("visibility bunny", 100, 1000);  // 60 in 4 s: 15/s, 900 left → 60 s
  EXPECT_EQ(f.out, "\r[visibility bunny]  10% (100/1000), 1 min 00 s left\x1b[K");
}

TEST(Progress, TerminalRedrawsInPlaceAndEndsWithANewline) {
  Fixture f;
  f.options.terminal = true;
  ProgressReporter p = f.make();
  p.update("visibility bunny", 0, 4);
  f.now += 3.0;
  p.update("visibility bunny", 1, 4);
  f.now += 0.05;  // within the redraw interval: not drawn
  p.update("visibility bunny", 2, 4);
  f.now += 0.2;
  p.update("visibility bunny", 3, 4);
  f.now += 0.75;
  p.update("visibility bunny", 4, 4);
  EXPECT_EQ(f.out,
            "\r[visibility bunny]  25% (1/4), 9.0 s left\x1b[K"
            "\r[visibility bunny]  75% (3/4), 1.1 s left\x1b[K"
            "\r[visibility bunny] 100% (4/4) in 4.0 s\x1b[K\n");
}

TEST(Progress, LogPrintsLinesEveryStepOrAfterSilence) {
  Fixture f;
  f.options.terminal = false;
  f.options.logPercentStep = 25;
  f.options.logSeconds = 10.0;
  ProgressReporter p = f.make();
  p.update("tables", 0, 100);
  for (int i = 1; i <= 100; ++i) {
    // 1 % per second up to 30 %, then 25 % per second.
    f.now += i <= 30 ? 1.0 : 0.04;
    p.update("tables", static_cast<std::size_t>(i), 100);
  }
  // From 2 s on: the first line, then one every 10 s while slow (the time
  // rule), then one per 25 % more while fast (the step rule), then the end.
  EXPECT_EQ(f.out,
            "[tables]   2% (2/100), 1 min 38 s left\n"
            "[tables]  12% (12/100), 1 min 28 s left\n"
            "[tables]  22% (22/100), 1 min 18 s left\n"
            "[tables]  47% (47/100), 35 s left\n"
            "[tables]  72% (72/100), 12 s left\n"
            "[tables]  97% (97/100), 1.0 s left\n"
            "[tables] 100% (100/100) in 33 s\n");
}

TEST(Progress, LogLineAfterASilenceIsNotRepeatedAtTheNextRoundPercentage) {
  Fixture f;
  f.options.terminal = false;
  f.options.logPercentStep = 10;
  f.options.logSeconds = 9.0;
  ProgressReporter p = f.make();
  p.update("visibility", 0, 100);
  for (int i = 1; i < 32; ++i) {
    f.now += 1.0;
    p.update("visibility", static_cast<std::size_t>(i), 100);
  }
  // 2 (first), 11 (9 s), 20 (9 s), 29 (9 s): never 29 and then 30.
  EXPECT_EQ(f.out,
            "[visibility]   2% (2/100), 1 min 38 s left\n"
            "[visibility]  11% (11/100), 1 min 29 s left\n"
            "[visibility]  20% (20/100), 1 min 20 s left\n"
            "[visibility]  29% (29/100), 1 min 11 s left\n");
}

TEST(Progress, NeverShowsOneHundredBeforeTheEnd) {
  Fixture f;
  f.options.terminal = false;
  ProgressReporter p = f.make();
  p.update("visibility", 0, 1000);
  f.now += 5.0;
  p.update("visibility", 999, 1000);
  EXPECT_NE(f.out.find("[visibility]  99% (999/1000)"), std::string::npos) << f.out;
}

TEST(Progress, NestedStagesKeepTheirOwnClock) {
  Fixture f;
  f.options.terminal = false;
  f.options.logPercentStep = 50;
  ProgressReporter p = f.make();
  p.update("eval tables", 0, 4);
  f.now += 1.0;
  p.update("visibility bunny", 0, 10);
  f.now += 5.0;
  p.update("visibility bunny", 10, 10);  // 5 s, but no update between start and end: nothing to show
  p.update("eval tables", 1, 4);         // 6 s for 1 of 4: 18 s left
  EXPECT_EQ(f.out, "[eval tables]  25% (1/4), 18 s left\n");
}

TEST(Progress, MessagesDoNotGarbleTheTerminalLine) {
  Fixture f;
  f.options.terminal = true;
  ProgressReporter p = f.make();
  p.update("tables", 0, 10);
  f.now += 4.0;
  p.update("tables", 2, 10);
  f.out.clear();
  p.message("[eval] table level 5 grace: 170.86 dB");
  EXPECT_EQ(f.out,
            "\r\x1b[K[eval] table level 5 grace: 170.86 dB\n"
            "\r[tables]  20% (2/10), 16 s left\x1b[K");
}

TEST(Progress, DetailReplacesTheCountsAndFinishEndsEarly) {
  Fixture f;
  f.options.terminal = false;
  f.options.prefix = "[serve] ";
  ProgressReporter p = f.make();
  p.update("reference", 0, 4096, "0 samples/pixel");
  f.now += 3.0;
  p.update("reference", 1024, 4096, "1024 samples/pixel, half-image difference 0.0200");
  f.now += 1.0;
  p.finish("reference", "1536 samples/pixel, half-image difference 0.0099");
  EXPECT_EQ(f.out,
            "[serve] [reference]  25% 1024 samples/pixel, half-image difference 0.0200, 9.0 s left\n"
            "[serve] [reference] 100% 1536 samples/pixel, half-image difference 0.0099 in 4.0 s\n");
}

TEST(Progress, SamplesToConvergeFollowOneOverRootN) {
  // Error 0.04 at 256 samples, goal 0.01: (0.04/0.01)² = 16 times as many.
  EXPECT_EQ(estimatedSamplesToConverge(256, 0.04, 0.01, 65536), 4096u);
  EXPECT_EQ(estimatedSamplesToConverge(256, 0.4, 0.01, 65536), 65536u) << "capped";
  EXPECT_EQ(estimatedSamplesToConverge(256, 0.005, 0.01, 65536), 256u) << "never fewer than taken";
  EXPECT_EQ(estimatedSamplesToConverge(256, 0.04, 0.0, 65536), 65536u) << "no tolerance: all samples";
}

}  // namespace
}  // namespace haarcast::app
