// The accuracy targets on a simulated 10-minute drive (IMU 100 Hz, GNSS 10 Hz with
// sigma 1 m), for the InEKF with the quaternion ESKF side by side. The figures are printed so
// the closing note can quote them; both filters are user-selectable and held to the targets
// (the ESKF's 180-degree heading recovery is reported only: it is not designed for it).
#include <gtest/gtest.h>

#include <cstdio>
#include <numbers>

#include "semap/estimation/evaluation.hpp"
#include "semap/estimation/so3.hpp"
#include "semap/sim/drive_simulator.hpp"

namespace semap::estimation {
namespace {

constexpr int kRuns = 3;  // Monte-Carlo runs for the NEES average

struct Figures {
  double ate = 0, heading = 0;
  NeesSummary nees;
};

Figures drive(FilterKind kind) {
  Figures f;
  std::vector<std::vector<double>> nees;
  EvaluationOptions options;
  options.metrics_after_s = 30.0;  // after the heading has converged from the 17 deg guess
  options.motion_start_s = 2.0;
  for (int run = 0; run < kRuns; ++run) {
    sim::SimulatorConfig sc;
    sc.duration_s = 600.0;
    sc.seed = 100 + static_cast<std::uint64_t>(run);
    const DriveData data = sim::simulate(sc);
    EstimatorConfig ec;
    ec.filter = kind;
    const EvaluationRun r = run_evaluation(data, ec, options);
    f.ate += r.metrics.ate_rmse_m / kRuns;
    f.heading += r.metrics.heading_rmse_deg / kRuns;
    std::vector<double> series;
    for (const auto& s : r.samples) {
      if (s.t >= options.metrics_after_s) series.push_back(s.nees);
    }
    nees.push_back(std::move(series));
  }
  f.nees = summarise_nees(nees, 9);
  std::printf(
      "[%s] 10-min drive: ATE %.3f m, heading RMSE %.3f deg, ANEES %.2f (95%% bounds "
      "%.2f..%.2f over %d runs), inside %.0f%% of steps\n",
      kind == FilterKind::kLeftInekf ? "InEKF" : "ESKF", f.ate, f.heading, f.nees.average,
      f.nees.lower_bound, f.nees.upper_bound, kRuns, 100.0 * f.nees.fraction_inside);
  return f;
}

TEST(Accuracy, TenMinuteDrive) {
  const Figures inekf = drive(FilterKind::kLeftInekf);
  const Figures eskf = drive(FilterKind::kQuaternionEskf);
  EXPECT_LE(inekf.ate, 0.5);
  EXPECT_LE(inekf.heading, 1.0);
  EXPECT_GE(inekf.nees.average, inekf.nees.lower_bound);
  EXPECT_LE(inekf.nees.average, inekf.nees.upper_bound);
  EXPECT_LE(eskf.ate, 0.5);
  EXPECT_LE(eskf.heading, 1.0);
  EXPECT_GE(eskf.nees.average, eskf.nees.lower_bound);
  EXPECT_LE(eskf.nees.average, eskf.nees.upper_bound);
}

double settle_from_180(FilterKind kind, std::uint64_t seed) {
  sim::SimulatorConfig sc;
  sc.duration_s = 60.0;
  sc.seed = seed;
  const DriveData data = sim::simulate(sc);
  EstimatorConfig ec;
  ec.filter = kind;
  ec.init.yaw_rad = yaw_of(data.truth.front().state.rotation) + std::numbers::pi;
  EvaluationOptions options;
  options.motion_start_s = sc.static_s;
  const EvaluationRun r = run_evaluation(data, ec, options);
  return r.metrics.heading_settle_s;
}

TEST(Accuracy, HeadingConvergesFrom180Degrees) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const double inekf = settle_from_180(FilterKind::kLeftInekf, seed);
    const double eskf = settle_from_180(FilterKind::kQuaternionEskf, seed);
    std::printf(
        "seed %lu, 180 deg initial heading error: below 2 deg after %.1f s of driving "
        "(InEKF), %s (ESKF: %.1f s)\n",
        static_cast<unsigned long>(seed), inekf, eskf < 0 ? "never" : "settled", eskf);
    EXPECT_GE(inekf, 0.0);
    EXPECT_LT(inekf, 20.0);
  }
}

}  // namespace
}  // namespace semap::estimation
