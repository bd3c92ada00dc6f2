#include "semap/estimation/metrics.hpp"

#include <gtest/gtest.h>

#include <random>

#include "semap/estimation/chi_square.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {
namespace {

std::vector<Pose3> circle(double yaw_offset, const Eigen::Vector3d& shift) {
  std::vector<Pose3> out;
  for (int i = 0; i < 100; ++i) {
    const double a = 0.05 * i;
    out.push_back({rotation_from_rpy(0, 0, a + M_PI / 2 + yaw_offset),
                   Eigen::Vector3d(10 * std::cos(a), 10 * std::sin(a), 0) + shift});
  }
  return out;
}

TEST(Metrics, AteHeadingAndRpe) {
  const auto truth = circle(0.0, Eigen::Vector3d::Zero());
  const auto shifted = circle(0.0, Eigen::Vector3d(3.0, 4.0, 0.0));
  EXPECT_NEAR(ate_rmse(shifted, truth), 5.0, 1e-12);
  EXPECT_NEAR(heading_rmse_deg(shifted, truth), 0.0, 1e-9);
  // A constant offset does not change relative motion.
  const auto rpe = relative_pose_error(shifted, truth, 10);
  EXPECT_NEAR(rpe.translation_rmse_m, 0.0, 1e-9);
  EXPECT_EQ(rpe.pairs, 90u);
  const auto turned = circle(2.0 * M_PI / 180.0, Eigen::Vector3d::Zero());
  EXPECT_NEAR(heading_rmse_deg(turned, truth), 2.0, 1e-9);
  EXPECT_GT(relative_pose_error(turned, truth, 10).translation_rmse_m, 0.01);
  EXPECT_THROW(ate_rmse({}, truth), std::invalid_argument);
}

TEST(Metrics, ChiSquareQuantilesAndNeesBounds) {
  EXPECT_NEAR(chi_square_quantile(0.999, 3), 16.2662, 1e-3);
  EXPECT_NEAR(chi_square_quantile(0.025, 9), 2.7004, 1e-3);
  EXPECT_NEAR(chi_square_quantile(0.975, 9), 19.0228, 1e-3);
  EXPECT_THROW(chi_square_quantile(1.0, 3), std::invalid_argument);

  // Consistent samples: e ~ N(0, P) gives NEES ~ chi2(dof), inside the bounds ~95 % of the time.
  std::mt19937_64 rng(2);
  std::normal_distribution<double> n(0.0, 1.0);
  const int dof = 3;
  std::vector<std::vector<double>> runs(10, std::vector<double>(2000));
  for (auto& run : runs) {
    for (auto& v : run) {
      const Eigen::Vector3d e(n(rng), 2.0 * n(rng), 0.5 * n(rng));
      v = nees(e, Eigen::Vector3d(1.0, 4.0, 0.25).asDiagonal().toDenseMatrix());
    }
  }
  const NeesSummary s = summarise_nees(runs, dof);
  EXPECT_NEAR(s.average, 3.0, 0.05);
  EXPECT_NEAR(s.lower_bound, chi_square_quantile(0.025, 30) / 10, 1e-9);
  EXPECT_NEAR(s.fraction_inside, 0.95, 0.02);
  // An overconfident filter (errors twice the claimed sigma) falls outside.
  for (auto& run : runs)
    for (auto& v : run) v *= 4.0;
  EXPECT_LT(summarise_nees(runs, dof).fraction_inside, 0.05);
}

TEST(Metrics, SettlingTime) {
  const std::vector<double> t = {0, 1, 2, 3, 4, 5};
  EXPECT_DOUBLE_EQ(settling_time(t, {10, 5, 1, 3, 1, 0.5}, 2.0), 4.0);
  EXPECT_DOUBLE_EQ(settling_time(t, {1, 1, 1, 1, 1, 1}, 2.0), 0.0);
  EXPECT_LT(settling_time(t, {1, 1, 1, 1, 1, 5}, 2.0), 0.0);
}

}  // namespace
}  // namespace semap::estimation
