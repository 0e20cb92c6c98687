// A long frame's progress (frame_progress.h): the fraction of the frame from
// its stage and the renderer's last frame, and the tracker's rule with a
// made-up clock — nothing before half a second, then at most four a second,
// a fraction that never goes back, and an estimate of the time left.
#include "haarcast/net/frame_progress.h"

#include <chrono>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "haarcast/net/messages.h"

namespace haarcast::net {
namespace {

using namespace std::chrono_literals;
using TrackerClock = FrameProgressTracker::Clock;

const std::vector<render::StageTime> kLast = {{"light", 0.1}, {"gbuffer", 0.2}, {"fused", 1.5}, {"tonemap", 0.2}};

TEST(FrameFraction, StagesAreWeightedByTheLastFramesTimes) {
  EXPECT_DOUBLE_EQ(*frameFraction("light", 0.0, kLast), 0.0);
  EXPECT_DOUBLE_EQ(*frameFraction("gbuffer", 0.5, kLast), (0.1 + 0.1) / 2.0);
  EXPECT_DOUBLE_EQ(*frameFraction("fused", 0.0, kLast), 0.3 / 2.0);
  EXPECT_DOUBLE_EQ(*frameFraction("fused", 1.0, kLast), 1.8 / 2.0);
  EXPECT_DOUBLE_EQ(*frameFraction("tonemap", 2.0, kLast), 1.0) << "a stage fraction past 1 is taken as 1";
  EXPECT_DOUBLE_EQ(*frameFraction(kQueuedStage, 0.0, kLast), 0.0);
  EXPECT_FALSE(frameFraction("splitsum", 0.5, kLast)) << "a stage the last frame did not have says nothing";
  EXPECT_FALSE(frameFraction("fused", 0.5, {})) << "no weights, no fraction";
}

TEST(FrameFraction, EachMethodsDefaultSharesSumToOneAndNameItsShadingStage) {
  for (const RotationMethod m : kAllPixelMethods) {
    const std::vector<render::StageTime> shares = defaultStageShares(m);
    double sum = 0.0;
    for (const auto& s : shares) sum += s.seconds;
    EXPECT_NEAR(sum, 1.0, 1e-9) << methodName(m);
    const char* shading = m == RotationMethod::Fused ? "fused" : m == RotationMethod::Splitsum ? "splitsum" : "rotation";
    EXPECT_TRUE(frameFraction(shading, 0.5, shares)) << methodName(m);
  }
}

TEST(FrameProgressTracker, NothingBeforeHalfASecondThenFourASecondAndNeverBack) {
  const auto t0 = TrackerClock::time_point{} + 1h;
  FrameProgressTracker tracker(t0, RotationMethod::Fused, kLast, 1000, 1000);
  render::StageMark mark;
  EXPECT_FALSE(tracker.poll(mark, t0 + 100ms));
  EXPECT_FALSE(tracker.poll(mark, t0 + 499ms));
  // Queued: no render thread has it yet.
  auto queued = tracker.poll(mark, t0 + 500ms);
  ASSERT_TRUE(queued);
  EXPECT_EQ(queued->stage, kQueuedStage);
  EXPECT_EQ(queued->fraction, 0.0);
  EXPECT_EQ(queued->secondsLeft, 0.0) << "no estimate before the render starts";
  EXPECT_DOUBLE_EQ(queued->elapsedSeconds, 0.5);
  EXPECT_FALSE(tracker.poll(mark, t0 + 700ms)) << "within the interval";

  // gbuffer, 10 of 10 tiles: the frame at (0.1 + 0.2) / 2.
  mark.enter("gbuffer", 10);
  for (int i = 0; i < 10; ++i) mark.tick();
  auto gbuffer = tracker.poll(mark, t0 + 750ms);
  ASSERT_TRUE(gbuffer);
  EXPECT_EQ(gbuffer->stage, "gbuffer");
  EXPECT_DOUBLE_EQ(gbuffer->stageFraction, 1.0);
  EXPECT_DOUBLE_EQ(gbuffer->fraction, 0.15);
  // The fused stage, half done; then a stage the weights do not know (the
  // fraction holds, the stage is still said); then back to a stage that
  // reads lower (a watcher that saw an earlier stage late): never back.
  mark.enter("fused", 100);
  for (int i = 0; i < 50; ++i) mark.tick();
  auto fused = tracker.poll(mark, t0 + 1000ms);
  ASSERT_TRUE(fused);
  EXPECT_DOUBLE_EQ(fused->fraction, (0.3 + 0.75) / 2.0);
  // At its rate so far (0.525 of the frame in 0.3 s of rendering, from the
  // last poll that saw it queued) the rest takes 0.3 · 0.475 / 0.525 s.
  EXPECT_NEAR(fused->secondsLeft, 0.3 * (1.0 - 0.525) / 0.525, 1e-9);
  mark.enter("shadow-rays", 0);
  auto unknown = tracker.poll(mark, t0 + 1250ms);
  ASSERT_TRUE(unknown);
  EXPECT_EQ(unknown->stage, "shadow-rays");
  EXPECT_DOUBLE_EQ(unknown->fraction, fused->fraction);
  mark.enter("gbuffer", 10);
  auto late = tracker.poll(mark, t0 + 1500ms);
  ASSERT_TRUE(late);
  EXPECT_DOUBLE_EQ(late->fraction, fused->fraction);
}

TEST(FrameProgressTracker, BeforeATenthTheEstimateIsTheLastFrameScaledByPixels) {
  const auto t0 = TrackerClock::time_point{} + 1h;
  // The last frame: 2 s at 1000 pixels; this one has 4000: about 8 s.
  FrameProgressTracker tracker(t0, RotationMethod::Fused, kLast, 1000, 4000);
  render::StageMark mark;
  mark.enter("light");
  // Never seen queued: its render counts from the order.
  auto first = tracker.poll(mark, t0 + 600ms);
  ASSERT_TRUE(first);
  EXPECT_NEAR(first->secondsLeft, 8.0 - 0.6, 1e-9);
  auto second = tracker.poll(mark, t0 + 1600ms);
  ASSERT_TRUE(second);
  EXPECT_NEAR(second->secondsLeft, 8.0 - 1.6, 1e-9);
  // A renderer's first frame: default shares, no estimate before a tenth.
  FrameProgressTracker fresh(t0, RotationMethod::Fused, {}, 0, 4000);
  auto none = fresh.poll(mark, t0 + 600ms);
  ASSERT_TRUE(none);
  EXPECT_EQ(none->secondsLeft, 0.0);
  EXPECT_EQ(none->fraction, 0.0);
}

TEST(FrameProgressMessage, CarriesTheUpdateClampedAndTheFramesSize) {
  FrameProgressUpdate u;
  u.stage = "fused";
  u.stageFraction = 1.5;
  u.fraction = 0.4;
  u.elapsedSeconds = 2.0;
  u.secondsLeft = -1.0;
  v1::ServerMessage m;
  ASSERT_TRUE(m.ParseFromString(frameProgressMessage(u, 640, 360)));
  ASSERT_TRUE(m.has_frame_progress());
  const auto& p = m.frame_progress();
  EXPECT_EQ(p.stage(), "fused");
  EXPECT_EQ(p.stage_fraction(), 1.0);
  EXPECT_EQ(p.fraction(), 0.4);
  EXPECT_EQ(p.elapsed_seconds(), 2.0);
  EXPECT_EQ(p.estimated_seconds_left(), 0.0);
  EXPECT_EQ(p.width(), 640u);
  EXPECT_EQ(p.height(), 360u);
}

}  // namespace
}  // namespace haarcast::net
