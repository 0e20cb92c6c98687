#include "haarcast/core/metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace haarcast {
namespace {

TEST(Metrics, AnalyticPsnr) {
  // One error of 1 in four values: MSE = 1/4, peak = 3, PSNR = 10·log10(9/(1/4)) = 10·log10(36).
  const std::vector<double> reference{0.0, 1.0, 2.0, 3.0};
  const std::vector<double> test{0.0, 1.0, 2.0, 4.0};
  const ErrorStats stats = compareSignals(reference, test);
  EXPECT_DOUBLE_EQ(stats.mse, 0.25);
  EXPECT_DOUBLE_EQ(stats.peak, 3.0);
  EXPECT_NEAR(stats.psnr, 10.0 * std::log10(36.0), 1e-12);
}

TEST(Metrics, UniformErrorOfOneTenthOfPeakIsTwentyDecibels) {
  const std::vector<double> reference{1.0, 0.5, 1.0, 0.25};
  const std::vector<double> test{1.1, 0.4, 0.9, 0.35};
  const ErrorStats stats = compareSignals(reference, test);
  EXPECT_NEAR(stats.mse, 0.01, 1e-15);
  EXPECT_NEAR(stats.psnr, 20.0, 1e-12);
}

TEST(Metrics, PeakIsTheReferenceMaximumNotTheTests) {
  // MSE = (0 + 4)/2 = 2 with peak 2 from the reference: 10·log10(4/2).
  const std::vector<double> reference{0.0, 2.0};
  const std::vector<double> test{0.0, 4.0};
  const ErrorStats stats = compareSignals(reference, test);
  EXPECT_DOUBLE_EQ(stats.peak, 2.0);
  EXPECT_DOUBLE_EQ(stats.mse, 2.0);
  EXPECT_NEAR(stats.psnr, 10.0 * std::log10(2.0), 1e-12);
}

TEST(Metrics, IdenticalSignalsHaveInfinitePsnr) {
  const std::vector<double> signal{0.5, 2.0, -1.0};
  const ErrorStats stats = compareSignals(signal, signal);
  EXPECT_EQ(stats.mse, 0.0);
  EXPECT_EQ(stats.peak, 2.0);
  EXPECT_TRUE(std::isinf(stats.psnr) && stats.psnr > 0.0);
}

TEST(Metrics, FloatOverloadAgreesWithDouble) {
  const std::vector<float> reference{0.0f, 1.0f, 2.0f, 3.0f};
  const std::vector<float> test{0.0f, 1.0f, 2.0f, 4.0f};
  const ErrorStats stats = compareSignals(reference, test);
  EXPECT_DOUBLE_EQ(stats.mse, 0.25);
  EXPECT_DOUBLE_EQ(stats.peak, 3.0);
  EXPECT_NEAR(stats.psnr, 10.0 * std::log10(36.0), 1e-12);
  EXPECT_TRUE(std::isinf(compareSignals(reference, reference).psnr));
}

TEST(Metrics, EmptyOrMismatchedLengthsThrow) {
  const std::vector<double> empty;
  const std::vector<double> two{1.0, 2.0};
  const std::vector<double> three{1.0, 2.0, 3.0};
  EXPECT_THROW(compareSignals(empty, empty), std::invalid_argument);
  EXPECT_THROW(compareSignals(two, three), std::invalid_argument);
  EXPECT_THROW(compareSignals(three, two), std::invalid_argument);
  const std::vector<float> emptyF;
  const std::vector<float> twoF{1.0f, 2.0f};
  EXPECT_THROW(compareSignals(emptyF, emptyF), std::invalid_argument);
  EXPECT_THROW(compareSignals(twoF, emptyF), std::invalid_argument);
}

}  // namespace
}  // namespace haarcast
