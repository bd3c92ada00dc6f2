#include "semap/estimation/rts_smoother.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <map>
#include <random>

#include "drive_fixtures.hpp"
#include "semap/estimation/estimator.hpp"
#include "semap/estimation/so3.hpp"
#include "semap/sim/drive_simulator.hpp"

namespace semap::estimation {
namespace {

using Eigen::Matrix2d;
using Eigen::MatrixXd;
using Eigen::Vector2d;
using Eigen::VectorXd;
using Space = EuclideanSpace<2>;

// A constant-velocity track (position, velocity) with position measurements.
struct CvModel {
  double dt = 0.1;
  double q = 0.5;  // acceleration noise density
  double r = 0.3;  // measurement variance
  Matrix2d f() const { return (Matrix2d() << 1.0, dt, 0.0, 1.0).finished(); }
  Matrix2d noise() const {
    return q * (Matrix2d() << dt * dt * dt / 3, dt * dt / 2, dt * dt / 2, dt).finished();
  }
};

// The Kalman filter's forward pass as rts_smooth takes it.
std::vector<RtsStep<Space>> kalman_forward(const CvModel& m, const Vector2d& x0, const Matrix2d& p0,
                                           const std::vector<double>& z) {
  const Eigen::RowVector2d h(1.0, 0.0);
  std::vector<RtsStep<Space>> steps;
  Vector2d x = x0;
  Matrix2d p = p0;
  for (std::size_t k = 0; k < z.size(); ++k) {
    RtsStep<Space> s;
    s.transition = m.f();
    if (k > 0) {
      x = m.f() * x;
      p = m.f() * p * m.f().transpose() + m.noise();
    }
    s.predicted = x;
    s.predicted_covariance = p;
    const double innovation_var = h * p * h.transpose() + m.r;
    const Vector2d gain = p * h.transpose() / innovation_var;
    x += gain * (z[k] - h * x);
    p = (Matrix2d::Identity() - gain * h) * p;
    s.filtered = x;
    s.filtered_covariance = p;
    steps.push_back(s);
  }
  return steps;
}

// The smoothed track in closed form: the mean and covariance of all states given all
// measurements, from the information matrix of the whole batch (prior, dynamics, measurements).
struct Batch {
  VectorXd mean;
  MatrixXd covariance;
};
Batch batch_solution(const CvModel& m, const Vector2d& x0, const Matrix2d& p0,
                     const std::vector<double>& z) {
  const int n = static_cast<int>(z.size());
  MatrixXd info = MatrixXd::Zero(2 * n, 2 * n);
  VectorXd vec = VectorXd::Zero(2 * n);
  const Matrix2d p0_inv = p0.inverse();
  info.block<2, 2>(0, 0) += p0_inv;
  vec.segment<2>(0) += p0_inv * x0;
  const Matrix2d q_inv = m.noise().inverse();
  for (int k = 0; k + 1 < n; ++k) {
    // Residual x_{k+1} - F x_k with weight Q^-1: J = [-F, I].
    Eigen::Matrix<double, 2, 4> j;
    j << -m.f(), Matrix2d::Identity();
    info.block<4, 4>(2 * k, 2 * k) += j.transpose() * q_inv * j;
  }
  for (int k = 0; k < n; ++k) {
    info(2 * k, 2 * k) += 1.0 / m.r;
    vec(2 * k) += z[static_cast<std::size_t>(k)] / m.r;
  }
  Batch b;
  b.covariance = info.inverse();
  b.mean = b.covariance * vec;
  return b;
}

TEST(RtsSmoother, LinearConstantVelocityEqualsTheBatchSolution) {
  const CvModel m;
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> z;
  double pos = 0.0;
  double vel = 1.0;
  for (int k = 0; k < 40; ++k) {
    z.push_back(pos + std::sqrt(m.r) * noise(rng));
    vel += std::sqrt(m.q * m.dt) * noise(rng);
    pos += vel * m.dt;
  }
  const Vector2d x0(0.0, 0.0);
  const Matrix2d p0 = Matrix2d::Identity() * 4.0;
  const auto steps = kalman_forward(m, x0, p0, z);
  const auto smoothed = rts_smooth<Space>(steps);
  const Batch batch = batch_solution(m, x0, p0, z);
  ASSERT_EQ(smoothed.size(), z.size());
  for (std::size_t k = 0; k < z.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(2 * k);
    EXPECT_NEAR((smoothed[k].state - batch.mean.segment<2>(i)).norm(), 0.0, 1e-9) << k;
    EXPECT_NEAR((smoothed[k].covariance - batch.covariance.block<2, 2>(i, i)).norm(), 0.0, 1e-9)
        << k;
  }
  // The last step is the filter's; the first is far better known than the filter knew it.
  EXPECT_EQ(smoothed.back().state, steps.back().filtered);
  EXPECT_LT(smoothed.front().covariance(1, 1), 0.1 * steps.front().filtered_covariance(1, 1));
}

double heading_error(const Eigen::Quaterniond& q, const NavState& truth) {
  return std::abs(wrap_angle(yaw_of(q.toRotationMatrix()) - yaw_of(truth.rotation)));
}

// A drive that starts with an unknown heading (the simulated robot faces 0.3 rad; the filter
// guesses 0 with a 3 rad sigma): the smoothed poses of its first 12 s, smoothed at 20 s, have
// a far smaller heading error than the filter had at their stamps.
TEST(InekfRtsSmoother, SmoothingFixesTheHeadingOfTheFirstSeconds) {
  sim::SimulatorConfig sc = test::drive(20.0, 7);
  const DriveData data = sim::simulate(sc);
  EstimatorConfig config;
  config.anchor = data.origin;
  Estimator e(config);
  e.record_for_smoothing(30.0);
  std::map<std::int64_t, NavState> truth;
  std::map<std::int64_t, StampedPose> filtered;
  std::size_t g = 0;
  for (std::size_t i = 0; i < data.imu.size(); ++i) {
    const auto& imu = data.imu[i];
    while (g < data.gnss.size() && data.gnss[g].stamp <= imu.stamp) e.add_gnss(data.gnss[g++]);
    e.add_imu(imu);
    truth[imu.stamp.ns] = data.truth[i].state;
    if (const auto p = e.pose_at(e.filter_time())) filtered[p->stamp.ns] = *p;
  }
  const std::vector<StampedPose> smoothed = e.finish_smoothing();
  ASSERT_GT(smoothed.size(), 500u);
  const double t0 = smoothed.front().stamp.seconds();
  double filtered_sq = 0.0;
  double smoothed_sq = 0.0;
  double filtered_pos_sq = 0.0;
  double smoothed_pos_sq = 0.0;
  int n = 0;
  for (const auto& s : smoothed) {
    if (s.stamp.seconds() > t0 + 12.0) break;
    const auto t = truth.find(s.stamp.ns);
    const auto f = filtered.find(s.stamp.ns);
    if (t == truth.end() || f == filtered.end()) continue;
    filtered_sq += std::pow(heading_error(f->second.orientation, t->second), 2);
    smoothed_sq += std::pow(heading_error(s.orientation, t->second), 2);
    filtered_pos_sq += (f->second.position - t->second.position).squaredNorm();
    smoothed_pos_sq += (s.position - t->second.position).squaredNorm();
    ++n;
  }
  ASSERT_GT(n, 300);
  const double filtered_rms = std::sqrt(filtered_sq / n);
  const double smoothed_rms = std::sqrt(smoothed_sq / n);
  EXPECT_GT(filtered_rms, 0.05);  // the test is about something: 3 degrees and more
  EXPECT_LT(smoothed_rms, 0.25 * filtered_rms);
  EXPECT_LT(smoothed_rms, 0.03);  // 0.014 rad against 0.36 when written
  EXPECT_LT(smoothed_pos_sq, filtered_pos_sq);
  // The newest smoothed pose is the filter's.
  const StampedPose& last = smoothed.back();
  const auto f = filtered.find(last.stamp.ns);
  ASSERT_NE(f, filtered.end());
  EXPECT_LT((last.position - f->second.position).norm(), 1e-6);
}

// The record keeps the last `max_seconds`: older keyframes and their poses go.
TEST(InekfRtsSmoother, KeepsOnlyTheLastSecondsItIsGiven) {
  const DriveData data = sim::simulate(test::drive(20.0, 7));
  EstimatorConfig config;
  config.anchor = data.origin;
  Estimator e(config);
  e.record_for_smoothing(5.0);
  std::size_t g = 0;
  for (const auto& imu : data.imu) {
    while (g < data.gnss.size() && data.gnss[g].stamp <= imu.stamp) e.add_gnss(data.gnss[g++]);
    e.add_imu(imu);
  }
  const auto smoothed = e.finish_smoothing();
  ASSERT_FALSE(smoothed.empty());
  const double span = common::seconds_between(smoothed.back().stamp, smoothed.front().stamp);
  EXPECT_GT(span, 4.5);
  EXPECT_LT(span, 5.3);
  EXPECT_TRUE(e.finish_smoothing().empty());  // the record ended
}

}  // namespace
}  // namespace semap::estimation
