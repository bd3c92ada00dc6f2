// The quaternion ESKF is a user-selectable filter (`filter: eskf`): it is held to accuracy and
// gating bounds of the same kind as the InEKF's (estimator_test.cpp, accuracy_test.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "drive_fixtures.hpp"
#include "semap/estimation/evaluation.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {
namespace {

using Eigen::Vector3d;
using test::drive;
using test::heading_known;
using test::max_position_error_after;

// GNSS sigma 1 m per axis (1.7 m 3-D): the fused estimate must be well inside that.
TEST(Eskf, TwoMinuteDriveAccuracy) {
  for (const std::uint64_t seed : {11u, 12u}) {
    const DriveData data = sim::simulate(drive(120.0, seed));
    EvaluationOptions options;
    options.metrics_after_s = 30.0;
    options.motion_start_s = 2.0;
    const EvaluationRun run =
        run_evaluation(data, heading_known(data, FilterKind::kQuaternionEskf), options);
    std::printf("ESKF 2-min drive, seed %lu: ATE %.3f m, heading RMSE %.3f deg\n",
                static_cast<unsigned long>(seed), run.metrics.ate_rmse_m,
                run.metrics.heading_rmse_deg);
    EXPECT_LE(run.metrics.ate_rmse_m, 0.5) << "seed " << seed;
    EXPECT_LE(run.metrics.heading_rmse_deg, 1.0) << "seed " << seed;
    EXPECT_LT(max_position_error_after(run, 30.0), 2.0) << "seed " << seed;
  }
}

// Normal fixes are accepted: at a 0.999 gate a clean drive loses at most a handful.
TEST(Eskf, AcceptsNormalFixes) {
  const DriveData data = sim::simulate(drive(90.0));
  const EvaluationRun run =
      run_evaluation(data, heading_known(data, FilterKind::kQuaternionEskf), {});
  EXPECT_LE(run.counters.gnss_rejected, 3u);
  EXPECT_GE(run.counters.gnss_applied + run.counters.gnss_rejected + 30, data.gnss.size());
  EXPECT_EQ(run.counters.reanchors, 0u);
}

// Five fixes 50 m off (0.5 s at 10 Hz) are gated out, and nothing else.
TEST(Eskf, GatesATransientFiftyMetreJump) {
  sim::SimulatorConfig sc = drive(90.0);
  sc.jumps.push_back({60.0, 0.5, Vector3d(50.0, 0.0, 0.0)});
  const DriveData data = sim::simulate(sc);
  const EvaluationRun run =
      run_evaluation(data, heading_known(data, FilterKind::kQuaternionEskf), {});
  EXPECT_EQ(run.counters.gnss_rejected, 5u);
  EXPECT_EQ(run.counters.reanchors, 0u);
  EXPECT_LT(max_position_error_after(run, 30.0), 3.0);
}

// A single outlier of 8 m (about 8 sigma) is refused; the same drive without it refuses none
// of the fixes around it.
TEST(Eskf, GatesASingleOutlierFix) {
  sim::SimulatorConfig sc = drive(90.0);
  sc.jumps.push_back({45.0, 0.05, Vector3d(0.0, 8.0, 0.0)});
  const DriveData data = sim::simulate(sc);
  const EvaluationRun with =
      run_evaluation(data, heading_known(data, FilterKind::kQuaternionEskf), {});
  const DriveData clean_data = sim::simulate(drive(90.0));
  const EvaluationRun clean =
      run_evaluation(clean_data, heading_known(clean_data, FilterKind::kQuaternionEskf), {});
  EXPECT_EQ(with.counters.gnss_rejected, clean.counters.gnss_rejected + 1);
  EXPECT_LT(max_position_error_after(with, 30.0), 2.0);
}

}  // namespace
}  // namespace semap::estimation
