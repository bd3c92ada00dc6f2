// The dual-antenna heading update (docs/estimation.md (H1)-(H3)): its Jacobian, and what it
// does in the Estimator at rest, where nothing else makes the heading observable.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <random>

#include "semap/estimation/estimator.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {
namespace {

using common::Stamp;
using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kDeg = std::numbers::pi / 180.0;

TEST(HeadingJacobian, MatchesFiniteDifferencesInBodyAndWorldAxes) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(-1.2, 1.2);
  const double h = 1e-6;
  for (int trial = 0; trial < 50; ++trial) {
    const Matrix3d r = rotation_from_rpy(angle(rng), angle(rng), 2.5 * angle(rng));
    const Eigen::RowVector3d body = yaw_jacobian_body(r);
    const Eigen::RowVector3d world = yaw_jacobian_world(r);
    for (int axis = 0; axis < 3; ++axis) {
      const Vector3d d = h * Vector3d::Unit(axis);
      const double db = wrap_angle(yaw_of(r * gamma0(d)) - yaw_of(r * gamma0(-d))) / (2.0 * h);
      const double dw = wrap_angle(yaw_of(gamma0(d) * r) - yaw_of(gamma0(-d) * r)) / (2.0 * h);
      EXPECT_NEAR(body(axis), db, 1e-6) << "trial " << trial << " axis " << axis;
      EXPECT_NEAR(world(axis), dw, 1e-6) << "trial " << trial << " axis " << axis;
    }
  }
}

// A robot standing still, level but for a small tilt, at a true ENU yaw, or turning in place
// about the vertical: 100 Hz IMU and 10 Hz fixes at the origin, each with the receiver's
// heading when it reports one.
class StandingRobot {
 public:
  StandingRobot(const EstimatorConfig& config, double true_yaw)
      : estimator_(config), enu_(Geodetic{49.0, 8.4, 110.0}), yaw_(true_yaw) {}

  // Heading as a receiver reports it: clockwise from north, [0, 360), plus `error_deg`;
  // none with std::nullopt (a single antenna).
  void stand(double seconds, std::optional<double> error_deg = 0.0) {
    run(seconds, 0.0, [&](double yaw) -> std::optional<double> {
      if (!error_deg) return std::nullopt;
      return reported(yaw, *error_deg);
    });
  }
  // The same with the receiver's heading field as given.
  void stand_reporting(double seconds, double heading_deg) {
    run(seconds, 0.0, [&](double) { return heading_deg; });
  }
  // Turning at `yaw_rate` (rad/s), the heading of `lag_s` before each fix's stamp: a fix read
  // late.
  void turn(double seconds, double yaw_rate, double lag_s) {
    run(seconds, yaw_rate, [&](double yaw) { return reported(yaw - yaw_rate * lag_s, 0.0); });
  }

  double yaw_error_deg() const {
    return wrap_angle(yaw_of(estimator_.filter().state().rotation) - yaw_) / kDeg;
  }
  double yaw_sigma_deg() const {
    return std::sqrt(estimator_.filter().rotation_covariance_world()(2, 2)) / kDeg;
  }
  Estimator& estimator() { return estimator_; }

 private:
  static double reported(double yaw, double error_deg) {
    return std::fmod(90.0 - yaw / kDeg + error_deg + 720.0, 360.0);
  }

  void run(double seconds, double yaw_rate,
           const std::function<std::optional<double>(double yaw)>& heading) {
    const int steps = static_cast<int>(std::lround(seconds * 100.0));
    for (int k = 0; k < steps; ++k) {
      if (k % 10 == 0) {
        common::GnssFix fix;
        const Geodetic g = enu_.to_geodetic(Vector3d::Zero());
        fix.stamp = Stamp::from_seconds(t_ + 0.003);
        fix.latitude_deg = g.latitude_deg;
        fix.longitude_deg = g.longitude_deg;
        fix.altitude_m = g.altitude_m;
        fix.quality = common::FixQuality::kGps;
        fix.covariance = Matrix3d::Identity() * 0.25;
        fix.heading_deg = heading(yaw_ + 0.003 * yaw_rate);
        estimator_.add_gnss(fix);
      }
      // The sample at t holds over the interval before it: the turn of that interval.
      t_ += 0.01;
      yaw_ += 0.01 * yaw_rate;
      const Matrix3d r = rotation_from_rpy(0.02, -0.03, yaw_);
      common::ImuSample s;
      s.stamp = Stamp::from_seconds(t_);
      s.accel = r.transpose() * Vector3d(0, 0, 9.80665);
      s.gyro = r.transpose() * Vector3d(0, 0, yaw_rate);
      estimator_.add_imu(s);
    }
  }

  Estimator estimator_;
  LocalEnu enu_;
  double yaw_;
  double t_ = 1.0;
};

TEST(HeadingUpdate, HeadingConvergesAtRestFromAWrongStart) {
  for (const FilterKind kind : {FilterKind::kLeftInekf, FilterKind::kQuaternionEskf}) {
    EstimatorConfig config;
    config.filter = kind;  // guess 0 with the default "unknown" sigma (~172 deg)
    const double true_yaw = 170.0 * kDeg;
    StandingRobot with(config, true_yaw);
    with.stand(3.0);
    ASSERT_TRUE(with.estimator().initialised());
    EXPECT_LT(std::abs(with.yaw_error_deg()), 0.05) << static_cast<int>(kind);
    EXPECT_LT(with.yaw_sigma_deg(), 0.5) << static_cast<int>(kind);
    EXPECT_GT(with.estimator().counters().heading_applied, 15u);
    EXPECT_EQ(with.estimator().counters().heading_rejected, 0u);
    // Without a heading, standing still teaches the filter nothing about it.
    StandingRobot without(config, true_yaw);
    without.stand(3.0, std::nullopt);
    EXPECT_GT(std::abs(without.yaw_error_deg()), 160.0);
    EXPECT_GT(without.yaw_sigma_deg(), 90.0);
    EXPECT_EQ(without.estimator().counters().heading_applied, 0u);
  }
}

TEST(HeadingUpdate, AWrongHeadingIsGatedAndABadOneCounted) {
  EstimatorConfig config;
  const double true_yaw = -2.0;
  StandingRobot robot(config, true_yaw);
  robot.stand(3.0);
  const auto applied = robot.estimator().counters().heading_applied;
  ASSERT_LT(std::abs(robot.yaw_error_deg()), 0.05);
  // One epoch 20 degrees off (a baseline that lost its carrier-phase fix): gated out.
  robot.stand(0.1, 20.0);
  EXPECT_EQ(robot.estimator().counters().heading_rejected, 1u);
  EXPECT_EQ(robot.estimator().counters().heading_applied, applied);
  EXPECT_LT(std::abs(robot.yaw_error_deg()), 0.05);
  // Good headings go on being applied after it.
  robot.stand(1.0);
  EXPECT_EQ(robot.estimator().counters().heading_applied, applied + 10);
  EXPECT_EQ(robot.estimator().counters().heading_rejected, 1u);
  // A value no receiver reports is counted, never applied.
  robot.stand_reporting(0.1, 400.0);
  robot.stand_reporting(0.1, std::numeric_limits<double>::quiet_NaN());
  EXPECT_EQ(robot.estimator().counters().heading_invalid, 2u);
  EXPECT_LT(std::abs(robot.yaw_error_deg()), 0.05);
}

// A fix read 0.1 s after its epoch while turning at 0.5 rad/s: its heading is 2.9 degrees
// behind. The stamp's error term of (H2) takes it as the noise it is; without it most such
// headings fail the gate (and those that pass drag the heading back).
TEST(HeadingUpdate, ALateHeadingWhileTurningIsWeightedNotGated) {
  for (const double latency_s : {0.1, 0.0}) {
    EstimatorConfig config;
    config.gnss_heading_latency_s = latency_s;
    StandingRobot robot(config, 1.0);
    robot.stand(3.0);
    robot.turn(5.0, 0.5, 0.1);
    const auto& c = robot.estimator().counters();
    if (latency_s > 0.0) {
      // At most the turn's first fix, weighed with the yaw rate of the sample before it (0).
      EXPECT_LE(c.heading_rejected, 1u);
      EXPECT_GT(c.heading_applied, 65u);
      EXPECT_LT(std::abs(robot.yaw_error_deg()), 1.0);
    } else {
      EXPECT_GT(c.heading_rejected, 10u);
    }
  }
}

TEST(HeadingUpdate, TheBaselineOffsetTurnsTheReportedHeadingIntoTheBodys) {
  EstimatorConfig config;
  config.gnss_heading_offset_rad = 90.0 * kDeg;  // baseline across the robot, to its right
  const double true_yaw = 0.4;
  StandingRobot robot(config, true_yaw);
  // The receiver reports the baseline's heading: the body's plus 90 degrees clockwise.
  robot.stand(3.0, 90.0);
  EXPECT_LT(std::abs(robot.yaw_error_deg()), 0.05);
}

}  // namespace
}  // namespace semap::estimation
