#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "../mapping/toy_dataset.hpp"
#include "semap/map_io/label_noise.hpp"

namespace semap::map_io {
namespace {

using namespace semap::mapping;

// n points, true classes cycling through 1..3 (K = 4, class 0 free).
common::LabeledCloud cloud_of(std::size_t n) {
  common::LabeledCloud c;
  c.origin = Eigen::Vector3f(1.0f, 2.0f, 3.0f);
  for (std::size_t i = 0; i < n; ++i) {
    c.points.emplace_back(static_cast<float>(i), 0.0f, 0.0f);
    c.labels.push_back(static_cast<std::uint16_t>(1 + i % 3));
  }
  return c;
}

TEST(SoftLabelNoise, SoftLabelsAreDistributionsOverHitClassesWithTheArgmaxAsHardLabel) {
  const common::LabeledCloud clean = cloud_of(3000);
  const NoisySegmentation s = soft_label_noise(clean, {1.0, 1.0}, 1, 4, 7);
  ASSERT_EQ(s.soft.probabilities.size(), clean.size() * 4);
  EXPECT_TRUE(s.soft.labels.empty());
  EXPECT_EQ(s.soft.num_classes, 4);
  EXPECT_EQ(s.soft.points, clean.points);
  EXPECT_EQ(s.soft.origin, clean.origin);
  ASSERT_EQ(s.hard.labels.size(), clean.size());
  EXPECT_FALSE(s.hard.has_probabilities());
  EXPECT_EQ(s.hard.points, clean.points);
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < clean.size(); ++i) {
    const float* y = s.soft.probabilities.data() + i * 4;
    EXPECT_EQ(y[0], 0.0f) << i;
    float sum = 0.0f;
    for (int c = 1; c < 4; ++c) {
      EXPECT_GT(y[c], 0.0f) << i;
      sum += y[c];
    }
    EXPECT_NEAR(sum, 1.0f, 1e-6f) << i;
    EXPECT_EQ(s.hard.labels[i], std::max_element(y, y + 4) - y) << i;
    wrong += s.hard.labels[i] != clean.labels[i] ? 1 : 0;
  }
  EXPECT_EQ(s.wrong, wrong);
  EXPECT_GT(wrong, 0u);
}

TEST(SoftLabelNoise, ErrorRateIntegralMatchesClosedForms) {
  // No margin: the argmax is uniform, wrong (C - 1) / C of the time.
  EXPECT_NEAR(soft_label_error_rate({0.0, 1.0}, 3), 2.0 / 3.0, 1e-9);
  EXPECT_NEAR(soft_label_error_rate({0.0, 2.0}, 5), 4.0 / 5.0, 1e-9);
  // Two classes: wrong when sigma (n_other - n_true) > margin, P = Phi(-r / sqrt 2).
  for (const double r : {0.5, 1.0, 2.5}) {
    EXPECT_NEAR(soft_label_error_rate({2.0 * r, 2.0}, 2), 0.5 * std::erfc(r / 2.0), 1e-9) << r;
  }
  // Only the ratio matters, and more margin means fewer errors.
  EXPECT_NEAR(soft_label_error_rate({1.0, 1.0}, 3), soft_label_error_rate({3.0, 3.0}, 3), 1e-12);
  EXPECT_LT(soft_label_error_rate({2.0, 1.0}, 3), soft_label_error_rate({1.0, 1.0}, 3));
}

TEST(SoftLabelNoise, MeasuredArgmaxErrorRateMatchesTheExpectedOne) {
  const common::LabeledCloud clean = cloud_of(60000);
  for (const SoftLabelNoise noise :
       {SoftLabelNoise{1.0, 1.0}, SoftLabelNoise{3.0, 1.5}, SoftLabelNoise{0.5, 2.0}}) {
    const double expected = soft_label_error_rate(noise, 3);
    const double measured =
        static_cast<double>(soft_label_noise(clean, noise, 1, 4, 3).wrong) / clean.size();
    // Four standard errors of a binomial proportion.
    const double tolerance = 4.0 * std::sqrt(expected * (1.0 - expected) / clean.size());
    EXPECT_NEAR(measured, expected, tolerance) << noise.margin << " " << noise.sigma;
  }
}

TEST(SoftLabelNoise, CalibratedSegmenterHitsItsErrorRateAndIsCalibrated) {
  const common::LabeledCloud clean = cloud_of(60000);
  for (const double error : {0.05, 0.3, 0.5}) {
    const SoftLabelNoise noise = calibrated_soft_label_noise(error, 3);
    EXPECT_NEAR(noise.margin, noise.sigma * noise.sigma, 1e-12);
    EXPECT_NEAR(soft_label_error_rate(noise, 3), error, 1e-9);
    const NoisySegmentation s = soft_label_noise(clean, noise, 1, 4, 11);
    // Calibrated (P(t = c | y) = y_c): the mean top probability is the accuracy, and the
    // mean probability of the true class is the mean of sum_c y_c^2.
    double top = 0.0, true_class = 0.0, squares = 0.0;
    for (std::size_t i = 0; i < clean.size(); ++i) {
      const float* y = s.soft.probabilities.data() + i * 4;
      top += *std::max_element(y, y + 4);
      true_class += y[clean.labels[i]];
      for (int c = 0; c < 4; ++c) squares += y[c] * y[c];
    }
    const double n = static_cast<double>(clean.size());
    EXPECT_NEAR(static_cast<double>(s.wrong) / n, error, 0.01) << error;
    EXPECT_NEAR(top / n, 1.0 - static_cast<double>(s.wrong) / n, 0.01) << error;
    EXPECT_NEAR(true_class / n, squares / n, 0.01) << error;
  }
  EXPECT_THROW(calibrated_soft_label_noise(0.0, 3), std::invalid_argument);
  EXPECT_THROW(calibrated_soft_label_noise(0.7, 3), std::invalid_argument);
}

TEST(SoftLabelNoise, DeterministicForASeed) {
  const common::LabeledCloud clean = cloud_of(500);
  const NoisySegmentation a = soft_label_noise(clean, {1.0, 1.0}, 1, 4, 5);
  const NoisySegmentation b = soft_label_noise(clean, {1.0, 1.0}, 1, 4, 5);
  const NoisySegmentation c = soft_label_noise(clean, {1.0, 1.0}, 1, 4, 6);
  EXPECT_EQ(a.soft.probabilities, b.soft.probabilities);
  EXPECT_EQ(a.hard.labels, b.hard.labels);
  EXPECT_NE(a.soft.probabilities, c.soft.probabilities);
}

TEST(SoftLabelNoise, RejectsBadInput) {
  common::LabeledCloud clean = cloud_of(10);
  EXPECT_THROW(soft_label_noise(clean, {-1.0, 1.0}, 1, 4, 1), std::invalid_argument);
  EXPECT_THROW(soft_label_noise(clean, {1.0, NAN}, 1, 4, 1), std::invalid_argument);
  EXPECT_THROW(soft_label_noise(clean, {1.0, 1.0}, 3, 4, 1), std::invalid_argument);
  clean.labels[4] = 0;  // free is not a candidate class
  EXPECT_THROW(soft_label_noise(clean, {1.0, 1.0}, 1, 4, 1), std::invalid_argument);
  clean.labels[4] = 4;
  EXPECT_THROW(soft_label_noise(clean, {1.0, 1.0}, 1, 4, 1), std::invalid_argument);
}

TEST(SoftLabelNoise, SoftLabelsBeatTheirArgmaxUnderHeavyNoiseOnTheToyDataset) {
  const std::vector<common::LabeledCloud> scans = mapping::testing::toy_scans(1, 12);
  const std::vector<double> errors{0.3, 0.5};
  const auto rows = evaluate_soft_labels(scans, MapParams{}, errors, 1);
  ASSERT_EQ(rows.size(), 2u);
  for (const SoftLabelResult& row : rows) {
    EXPECT_NEAR(row.error, row.target_error, 0.02);
    EXPECT_GT(row.csm_soft, row.csm_hard + 0.03) << row.target_error;
  }
  // S-BKI gains clearly only at 50 % (about +0.07; about +0.01 at 30 %).
  EXPECT_GT(rows[1].bki_soft, rows[1].bki_hard + 0.03);
  EXPECT_GT(rows[0].bki_soft, rows[1].bki_soft);
}

}  // namespace
}  // namespace semap::map_io
