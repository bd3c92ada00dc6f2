#include "semap/sim/drive_simulator.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "semap/estimation/left_inekf.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::sim {
namespace {

// The simulated drive is scored with the filter's own types.
using namespace semap::estimation;

using Eigen::Vector3d;

SimulatorConfig noiseless(Scenario scenario) {
  sim::SimulatorConfig c;
  c.scenario = scenario;
  c.duration_s = 60.0;
  c.imu_noise.gyro_noise.setZero();
  c.imu_noise.accel_noise.setZero();
  c.imu_noise.gyro_bias_walk.setZero();
  c.imu_noise.accel_bias_walk.setZero();
  c.imu_noise.position_process = 0.0;
  c.initial_gyro_bias_sigma = 0.0;
  c.initial_accel_bias_sigma = 0.0;
  return c;
}

// A dual-antenna receiver's heading: the body x axis's true heading, clockwise from north,
// in [0, 360), with the configured noise.
TEST(Simulator, GnssHeadingIsTheTrueHeadingWithItsNoise) {
  SimulatorConfig c;
  c.duration_s = 60.0;
  c.gnss_heading = true;
  c.gnss_heading_sigma_deg = 0.3;
  const DriveData d = simulate(c);
  double sum2 = 0.0;
  std::size_t n = 0;
  std::size_t t = 0;
  for (const auto& fix : d.gnss) {
    ASSERT_TRUE(fix.heading_deg);
    ASSERT_GE(*fix.heading_deg, 0.0);
    ASSERT_LT(*fix.heading_deg, 360.0);
    while (t + 1 < d.truth.size() && d.truth[t + 1].stamp <= fix.stamp) ++t;
    // Between IMU samples: the nearer truth sample, at most 2.5 ms away.
    const double yaw = yaw_of(d.truth[t].state.rotation);
    const double error = wrap_angle((90.0 - *fix.heading_deg) * std::numbers::pi / 180.0 - yaw);
    sum2 += error * error;
    ++n;
  }
  ASSERT_GT(n, 500u);
  EXPECT_NEAR(std::sqrt(sum2 / static_cast<double>(n)) * 180.0 / std::numbers::pi, 0.3, 0.05);
  c.gnss_heading = false;
  EXPECT_FALSE(simulate(c).gnss.front().heading_deg);
}

// Dead reckoning on noise-free IMU samples must reproduce the truth: the samples and the
// ground truth come from the same motion.
TEST(Simulator, ImuIntegratesToTruth) {
  for (Scenario s : {sim::Scenario::kCar, sim::Scenario::kFigureEight, sim::Scenario::kLoops}) {
    const DriveData d = sim::simulate(noiseless(s));
    LeftInekf f(FilterParams{});
    f.reset(d.truth.front().state, Matrix15::Identity());
    for (std::size_t i = 1; i < d.imu.size(); ++i) {
      f.propagate(d.imu[i].gyro, d.imu[i].accel,
                  common::seconds_between(d.imu[i].stamp, d.imu[i - 1].stamp));
    }
    const NavState& truth = d.truth.back().state;
    EXPECT_LT((f.state().position - truth.position).norm(), 0.5);
    EXPECT_LT((f.state().velocity - truth.velocity).norm(), 0.02);
    EXPECT_LT(so3_log(f.state().rotation.transpose() * truth.rotation).norm(), 1e-3);
    // It actually moved.
    double path = 0.0;
    for (std::size_t i = 1; i < d.truth.size(); ++i) {
      path += (d.truth[i].state.position - d.truth[i - 1].state.position).norm();
    }
    EXPECT_GT(path, 400.0);
  }
}

// The loops drive is a figure eight of two circles 4 R across that comes back to the same
// place, heading and speed every two laps, so a long run covers the same ground again.
TEST(Simulator, LoopsRepeatEveryTwoLaps) {
  sim::SimulatorConfig c = noiseless(sim::Scenario::kLoops);
  c.loop_radius_m = 20.0;
  c.initial_yaw_rad = 0.0;  // the figure then lies along the axes of the box below
  const double two_laps_s =
      50.0;  // a whole number of IMU steps: the pairs compare sample by sample
  c.speed_m_s = 2.0 * 2.0 * std::numbers::pi * c.loop_radius_m / two_laps_s;
  c.duration_s = c.static_s + 8.0 + 7.0 * two_laps_s;
  const DriveData d = sim::simulate(c);
  const auto steps = static_cast<std::size_t>(std::lround(two_laps_s * c.imu_rate_hz));
  Eigen::AlignedBox3d box;
  for (const auto& s : d.truth) box.extend(s.state.position);
  EXPECT_NEAR(box.sizes().head<2>().maxCoeff(), 4.0 * c.loop_radius_m, 1.0);
  EXPECT_NEAR(box.sizes().head<2>().minCoeff(), 2.0 * c.loop_radius_m, 1.0);
  // From the second pair of laps on, every pair retraces the one before it.
  const std::size_t first = d.truth.size() - 5 * steps;
  for (std::size_t i = first; i + steps < d.truth.size(); i += steps / 7) {
    const auto& a = d.truth[i].state;
    const auto& b = d.truth[i + steps].state;
    EXPECT_LT((a.position - b.position).norm(), 0.01) << "at " << i;
    EXPECT_LT(so3_log(a.rotation.transpose() * b.rotation).norm(), 1e-4) << "at " << i;
  }
}

TEST(Simulator, GnssRateDropoutsJumpsAndOrdering) {
  sim::SimulatorConfig c = noiseless(sim::Scenario::kCar);
  c.gnss_sigma_m = 0.0;
  c.lever_arm = Vector3d(0.0, 0.0, 1.5);
  c.jumps.push_back({30.0, 2.0, Vector3d(0.0, 50.0, 0.0)});
  const DriveData d = sim::simulate(c);
  EXPECT_NEAR(static_cast<double>(d.gnss.size()), 600.0, 1.0);
  EXPECT_EQ(d.truth.size(), d.imu.size());
  for (std::size_t i = 1; i < d.gnss.size(); ++i) EXPECT_LT(d.gnss[i - 1].stamp, d.gnss[i].stamp);
  for (std::size_t i = 1; i < d.imu.size(); ++i) EXPECT_LT(d.imu[i - 1].stamp, d.imu[i].stamp);
  const LocalEnu enu(d.origin);
  // Fix 0 at rest: the antenna sits lever_arm above the body origin.
  const Vector3d p0 =
      enu.to_enu({d.gnss[0].latitude_deg, d.gnss[0].longitude_deg, d.gnss[0].altitude_m});
  EXPECT_LT((p0 - (d.truth[0].state.position + Vector3d(0, 0, 1.5))).norm(), 1e-3);
  int jumped = 0;
  for (const auto& f : d.gnss) {
    const double t = f.stamp.seconds() - 1.0;
    const std::size_t i = static_cast<std::size_t>(std::lround(t * 100.0));
    const Vector3d p = enu.to_enu({f.latitude_deg, f.longitude_deg, f.altitude_m});
    const NavState& s = d.truth[std::min(i, d.truth.size() - 1)].state;
    const double off = (p - s.position - s.rotation * c.lever_arm).y();
    if (off > 40.0) ++jumped;
  }
  EXPECT_EQ(jumped, 20);

  c.dropouts_per_minute = 6.0;
  c.dropout_duration_s = 3.0;
  const DriveData gaps = sim::simulate(c);
  EXPECT_LT(gaps.gnss.size(), d.gnss.size() - 60);
}

}  // namespace
}  // namespace semap::sim
