#include "semap/estimation/left_inekf.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <unsupported/Eigen/MatrixFunctions>

#include "semap/estimation/chi_square.hpp"
#include "semap/estimation/inekf_propagation.hpp"
#include "semap/estimation/kalman_update.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// A of the left-invariant error, as written in the issue.
Matrix15 error_dynamics(const Vector3d& w, const Vector3d& a) {
  Matrix15 m = Matrix15::Zero();
  m.block<3, 3>(kRot, kRot) = -skew(w);
  m.block<3, 3>(kVel, kRot) = -skew(a);
  m.block<3, 3>(kVel, kVel) = -skew(w);
  m.block<3, 3>(kPos, kVel).setIdentity();
  m.block<3, 3>(kPos, kPos) = -skew(w);
  m.block<3, 3>(kRot, kGyroBias) = -Matrix3d::Identity();
  m.block<3, 3>(kVel, kAccelBias) = -Matrix3d::Identity();
  return m;
}

Matrix15 random_spd(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Matrix15 l;
  for (int i = 0; i < 15; ++i)
    for (int j = 0; j < 15; ++j) l(i, j) = 0.2 * n(rng);
  return l * l.transpose() + 0.1 * Matrix15::Identity();
}

NavState some_state() {
  NavState s;
  s.rotation = rotation_from_rpy(0.1, -0.05, 2.0);
  s.velocity = Vector3d(3.0, -1.0, 0.2);
  s.position = Vector3d(100.0, -20.0, 5.0);
  return s;
}

// The state after one step with the increments of `step`, as the filter applies them.
NavState advance(const NavState& s, const InekfImuStep& step, const Vector3d& g) {
  NavState out = s;
  const double dt = step.dt;
  out.rotation = step.rotation;
  out.velocity = s.velocity + step.dv + g * dt;
  out.position = s.position + s.velocity * dt + step.dp + 0.5 * dt * dt * g;
  return out;
}

TEST(LeftInekf, WorldTransitionMatchesNumericalExpm) {
  struct Case {
    Vector3d w, a;
    double dt;
  };
  const Case cases[] = {
      {Vector3d(0.01, -0.02, 0.3), Vector3d(0.5, 0.1, 9.81), 0.01},
      {Vector3d(1.0, -2.0, 0.5), Vector3d(3.0, -4.0, 9.0), 0.0025},
      {Vector3d(0.0, 0.0, 0.0), Vector3d(0.0, 0.0, 9.81), 0.01},
      {Vector3d(2.0, 1.0, -3.0), Vector3d(-5.0, 2.0, 12.0), 0.02},
      {Vector3d(0.2, 0.1, 0.4), Vector3d(1.0, 0.5, 9.8), 0.1},
      {Vector3d(20.0, -5.0, 8.0), Vector3d(1.0, 0.5, 9.8), 0.1},  // 2.2 rad in one step
  };
  const FilterParams params;
  const NavState s = some_state();
  for (const auto& c : cases) {
    const InekfImuStep step =
        InekfImuStep::compute(s.rotation, s.velocity, s.position, c.w, c.a, c.dt, params.gravity);
    EXPECT_TRUE(step.rotation.isApprox(s.rotation * gamma0(c.w * c.dt), 1e-14));
    EXPECT_TRUE(step.dv.isApprox(s.rotation * gamma1(c.w * c.dt) * c.a * c.dt, 1e-14));
    EXPECT_TRUE(step.dp.isApprox(s.rotation * gamma2(c.w * c.dt) * c.a * c.dt * c.dt, 1e-14));
    // Phi_w = T(X+) expm(A dt) T(X)^-1 with A the left-invariant error dynamics.
    const Matrix15 left = (error_dynamics(c.w, c.a) * c.dt).exp();
    const Matrix15 numeric =
        world_from_left(advance(s, step, params.gravity)) * left * left_from_world(s);
    const Matrix15 closed = step.dense(params.gravity);
    // The gyro-bias couplings are truncated series: 1e-13 relative to their leading term.
    EXPECT_LT((closed - numeric).cwiseAbs().maxCoeff(), 1e-11 * std::max(1.0, numeric.norm()))
        << "w " << c.w.transpose() << " dt " << c.dt << "\n"
        << (closed - numeric);
  }
}

TEST(LeftInekf, AdjointMapsAreInverse) {
  const NavState s = some_state();
  EXPECT_LT((world_from_left(s) * left_from_world(s) - Matrix15::Identity()).norm(), 1e-12);
}

TEST(LeftInekf, CovariancePropagationEqualsDenseFormula) {
  std::mt19937_64 rng(3);
  FilterParams params;
  LeftInekf f(params);
  f.reset(some_state(), random_spd(rng));
  const Matrix15 p0 = f.covariance();
  const Vector3d gyro(0.1, -0.3, 0.7);
  const Vector3d accel(0.4, 0.2, 9.7);
  const double dt = 0.01;
  f.propagate(gyro, accel, dt);
  const Matrix15 phi = (error_dynamics(gyro, accel) * dt).exp();
  const Matrix15 q = process_noise_diagonal(params.noise).asDiagonal();
  const Matrix15 expected = phi * (p0 + q * dt) * phi.transpose();
  EXPECT_LT((f.covariance() - expected).norm(), 1e-11 * expected.norm());
}

// The world-form update must be the left-invariant EKF update, written here in its textbook
// form: H = [-[lever]x 0 I 0 0], z = R^T (y - p) - lever, N_b = R^T N R, X+ = X exp(K z).
TEST(LeftInekf, CorrectionEqualsTextbookLeftInvariantUpdate) {
  std::mt19937_64 rng(11);
  FilterParams params;
  LeftInekf f(params);
  f.reset(some_state(), random_spd(rng) * 0.1);
  for (int k = 0; k < 50; ++k) f.propagate(Vector3d(0.1, -0.2, 0.4), Vector3d(0.3, 0.1, 9.8), 0.01);
  const NavState x = f.state();
  const Matrix15 p = f.covariance();
  const Vector3d lever(0.4, -0.1, 1.1);
  const Vector3d y = x.position + x.rotation * lever + Vector3d(0.3, -0.2, 0.1);
  const Matrix3d n = Vector3d(0.04, 0.05, 0.09).asDiagonal();

  Matrix3x15 h = Matrix3x15::Zero();
  h.block<3, 3>(0, kRot) = -skew(lever);
  h.block<3, 3>(0, kPos).setIdentity();
  const Vector3d z = x.rotation.transpose() * (y - x.position) - lever;
  const Matrix3d nb = x.rotation.transpose() * n * x.rotation;
  const Matrix3d s = h * p * h.transpose() + nb;
  const Eigen::Matrix<double, 15, 3> gain = p * h.transpose() * s.inverse();
  const Vector15 delta = gain * z;
  const Matrix15 a = Matrix15::Identity() - gain * h;
  const Matrix15 p_expected = a * p * a.transpose() + gain * nb * gain.transpose();
  const Matrix3d g1 = gamma1(delta.head<3>());

  const CorrectionResult r = f.correct_position(y, n, lever, 1e9);
  ASSERT_TRUE(r.accepted);
  EXPECT_NEAR(r.mahalanobis2, z.dot(s.inverse() * z), 1e-9 * r.mahalanobis2);
  const NavState got = f.state();
  EXPECT_LT((got.rotation - x.rotation * gamma0(delta.head<3>())).norm(), 1e-12);
  EXPECT_LT((got.velocity - (x.velocity + x.rotation * g1 * delta.segment<3>(kVel))).norm(), 1e-10);
  EXPECT_LT((got.position - (x.position + x.rotation * g1 * delta.segment<3>(kPos))).norm(), 1e-10);
  EXPECT_LT((got.gyro_bias - delta.segment<3>(kGyroBias)).norm(), 1e-12);
  EXPECT_LT((f.covariance() - p_expected).norm(), 1e-10 * p_expected.norm());
}

// Log-linear property: with identical inputs, exp(xi) = X_hat^-1 X evolves exactly as
// xi_k = Phi_k ... Phi_1 xi_0, for any estimate and any finite error.
TEST(LeftInekf, PropagationIsInvariantAndLogLinear) {
  FilterParams params;
  const Vector3d xi_rot(0.3, -0.2, 0.9);
  const Vector3d xi_vel(1.0, -0.5, 0.2);
  const Vector3d xi_pos(4.0, 2.0, -1.0);
  std::vector<Vector3d> results;
  for (int base = 0; base < 2; ++base) {
    NavState est = some_state();
    if (base == 1) {
      est.rotation = rotation_from_rpy(-0.4, 0.3, -1.0);
      est.velocity = Vector3d(-7.0, 2.0, 0.0);
      est.position = Vector3d(-3.0, 50.0, 1.0);
    }
    NavState truth = est;  // X = X_hat exp(xi)
    truth.rotation = est.rotation * gamma0(xi_rot);
    truth.velocity = est.velocity + est.rotation * gamma1(xi_rot) * xi_vel;
    truth.position = est.position + est.rotation * gamma1(xi_rot) * xi_pos;
    LeftInekf fe(params);
    LeftInekf ft(params);
    fe.reset(est, Matrix15::Identity());
    ft.reset(truth, Matrix15::Identity());
    Eigen::Matrix<double, 9, 1> xi;
    xi << xi_rot, xi_vel, xi_pos;
    for (int k = 0; k < 200; ++k) {
      const double t = 0.01 * k;
      const Vector3d gyro(0.3 * std::sin(t), 0.2, 0.5 * std::cos(2 * t));
      const Vector3d accel(1.0 + std::sin(3 * t), 0.5, 9.8);
      fe.propagate(gyro, accel, 0.01);
      ft.propagate(gyro, accel, 0.01);
      xi = (error_dynamics(gyro, accel) * 0.01).exp().topLeftCorner<9, 9>() * xi;
    }
    const Vector15 e = fe.error_from(ft.state());
    EXPECT_LT((e.head<9>() - xi).norm(), 1e-9 * xi.norm()) << e.head<9>().transpose() << "\n"
                                                           << xi.transpose();
    results.push_back(e.head<3>());
  }
  // Same error evolution from two different estimates: the error dynamics are autonomous.
  EXPECT_LT((results[0] - results[1]).norm(), 1e-9);
}

// Noise large enough that every term of the deferred covariance (white noise carried to the
// end of the window, bias random walk and its coupling) shows at the compared precision.
// Different on every axis, as datasheets give it, so that noise entering through the wrong
// rotation shows.
FilterParams loud_params() {
  FilterParams params;
  params.noise.gyro_noise = Vector3d(2e-2, 1e-2, 4e-2);
  params.noise.accel_noise = Vector3d(0.2, 0.5, 0.1);
  params.noise.gyro_bias_walk = Vector3d(1e-2, 3e-2, 5e-3);
  params.noise.accel_bias_walk = Vector3d(0.1, 0.05, 0.3);
  params.noise.position_process = 0.05;
  return params;
}

double relative_difference(const Matrix15& a, const Matrix15& b) {
  return (a - b).norm() / b.norm();
}

// The textbook propagation in world form (what one-step mode runs) against
// expm(A dt) (P + Q dt) expm(A dt)^T in left-invariant coordinates, Q diagonal per body axis.
TEST(InekfPropagation, WorldFormEqualsLeftInvariantExpm) {
  std::mt19937_64 rng(31);
  std::normal_distribution<double> n(0.0, 1.0);
  const FilterParams params = loud_params();
  const Matrix15 q = process_noise_diagonal(params.noise).asDiagonal();
  for (int trial = 0; trial < 20; ++trial) {
    NavState s = some_state();
    s.rotation = rotation_from_rpy(n(rng), n(rng), 3.0 * n(rng));
    s.velocity = 10.0 * Vector3d(n(rng), n(rng), n(rng));
    const Vector3d w = (trial == 0 ? 20.0 : 1.0) * Vector3d(n(rng), n(rng), n(rng));
    const Vector3d a = Vector3d(n(rng), n(rng), 9.8 + n(rng));
    const double dt = trial == 0 ? 0.1 : 0.01;
    const InekfImuStep step =
        InekfImuStep::compute(s.rotation, s.velocity, s.position, w, a, dt, params.gravity);
    const Matrix15 p_left = random_spd(rng) * 0.01;
    const Matrix15 p_world = world_from_left(s) * p_left * world_from_left(s).transpose();
    const Matrix15 got = propagate_world_covariance(p_world, s, step, params);

    const Matrix15 phi = (error_dynamics(w, a) * dt).exp();
    const Matrix15 left = phi * (p_left + q * dt) * phi.transpose();
    const Matrix15 t_end = world_from_left(advance(s, step, params.gravity));
    const Matrix15 expected = t_end * left * t_end.transpose();
    EXPECT_LT(relative_difference(got, expected), 1e-11) << "trial " << trial;
  }
}

// A closed form: at zero covariance, with gyro noise on the body x axis only and a constant
// yaw rate, the world rotation covariance is qx dt sum_k u_k u_k^T, u_k = R_k e_x the body x
// axis at each step's start (the transition leaves the rotation block alone without bias
// uncertainty). Noise applied in world axes would give qx T diag(1, 0, 0) instead.
TEST(InekfPropagation, PerAxisGyroNoiseFollowsTheBodyAxes) {
  FilterParams params;
  params.noise.gyro_noise = Vector3d(3e-2, 0.0, 0.0);
  params.noise.accel_noise.setZero();
  params.noise.gyro_bias_walk.setZero();
  params.noise.accel_bias_walk.setZero();
  const double yaw_rate = 0.7;
  const double dt = 0.01;
  const int steps = 150;  // several windows
  NavState start;
  start.rotation = rotation_from_rpy(0.0, 0.0, 0.4);
  Matrix3d expected = Matrix3d::Zero();
  for (int k = 0; k < steps; ++k) {
    const double yaw = 0.4 + yaw_rate * dt * k;
    const Vector3d u(std::cos(yaw), std::sin(yaw), 0.0);
    expected += 9e-4 * dt * u * u.transpose();
  }
  for (const int window : {1, LeftInekf::kDefaultWindowSteps}) {
    LeftInekf f(params, window);
    f.reset(start, Matrix15::Zero());
    for (int k = 0; k < steps; ++k) {
      f.propagate(Vector3d(0.0, 0.0, yaw_rate), Vector3d(0.0, 0.0, 9.80665), dt);
    }
    EXPECT_LT((f.rotation_covariance_world() - expected).norm(), 1e-12 * expected.norm())
        << "window " << window << "\n"
        << f.rotation_covariance_world() << "\n"
        << expected;
  }
  EXPECT_GT(std::abs(expected(0, 1)), 0.1 * expected(0, 0));  // far from diag(1, 0, 0)
}

bool identical(const NavState& a, const NavState& b) {
  return a.rotation == b.rotation && a.velocity == b.velocity && a.position == b.position &&
         a.gyro_bias == b.gyro_bias && a.accel_bias == b.accel_bias;
}

// The deferred covariance (windows of up to 32 steps, formed only when read) against the
// textbook per-step propagation P <- expm(A dt) (P + Q dt) expm(A dt)^T in left-invariant
// coordinates, and against the filter in one-step mode (propagate_world_covariance), over
// 1000 random steps with random step lengths, per-axis noise, queries at every step of the
// first windows (so at both ends of each) and at random times after. Fast enough to pass the
// 100 m origin moves too.
TEST(LeftInekf, DeferredCovarianceEqualsPerStepPropagation) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const FilterParams params = loud_params();
  NavState start = some_state();
  start.velocity = Vector3d(25.0, -8.0, 1.0);
  start.gyro_bias = Vector3d(0.01, -0.02, 0.005);
  start.accel_bias = Vector3d(0.1, 0.05, -0.2);
  LeftInekf deferred(params);
  LeftInekf per_step(params, 1);
  const Matrix15 p0 = random_spd(rng) * 0.01;
  deferred.reset(start, p0);
  per_step.reset(start, p0);
  Matrix15 reference = deferred.covariance();
  const Matrix15 q = process_noise_diagonal(params.noise).asDiagonal();
  int queries = 0;
  double worst = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const Vector3d gyro = start.gyro_bias + Vector3d(0.3 * n(rng), 0.3 * n(rng), 0.5 * n(rng));
    const Vector3d accel = start.accel_bias + Vector3d(2.0 * n(rng), 2.0 * n(rng), 9.8 + n(rng));
    const double dt = 0.002 + 0.018 * u(rng);
    deferred.propagate(gyro, accel, dt);
    per_step.propagate(gyro, accel, dt);
    const Matrix15 phi =
        (error_dynamics(gyro - start.gyro_bias, accel - start.accel_bias) * dt).exp();
    reference = phi * (reference + q * dt) * phi.transpose();
    ASSERT_TRUE(identical(deferred.state(), per_step.state())) << "step " << k;
    if (k < 3 * LeftInekf::kDefaultWindowSteps || u(rng) < 0.1 || k == 999) {
      ++queries;
      const Matrix15 got = deferred.covariance();
      worst = std::max(worst, relative_difference(got, reference));
      EXPECT_LT(relative_difference(got, reference), 1e-9) << "step " << k;
      EXPECT_LT(relative_difference(got, per_step.covariance()), 1e-9) << "step " << k;
      EXPECT_LT(
          (deferred.position_covariance_world() - per_step.position_covariance_world()).norm(),
          1e-9 * per_step.position_covariance_world().norm());
      EXPECT_LT(
          (deferred.rotation_covariance_world() - per_step.rotation_covariance_world()).norm(),
          1e-9 * per_step.rotation_covariance_world().norm());
    }
  }
  EXPECT_GT(queries, 150);
  EXPECT_GT((deferred.state().position - start.position).norm(), 200.0);  // origin moved
  std::printf("deferred vs per-step expm covariance: worst relative difference %.2e\n", worst);
}

// Corrections end the window; reading the covariance does not, and does not change the result.
TEST(LeftInekf, DeferredFilterWithCorrectionsMatchesPerStepFilter) {
  std::mt19937_64 rng(23);
  std::normal_distribution<double> n(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const FilterParams params = loud_params();
  const double gate2 = chi_square_quantile(0.999, 3);
  LeftInekf deferred(params);
  LeftInekf per_step(params, 1);
  LeftInekf unread(params);  // never queried between corrections
  const Matrix15 p0 = random_spd(rng) * 0.01;
  deferred.reset(some_state(), p0);
  per_step.reset(some_state(), p0);
  unread.reset(some_state(), p0);
  const Vector3d lever(0.3, 0.1, 1.2);
  for (int k = 0; k < 1000; ++k) {
    const Vector3d gyro(0.2 * n(rng), 0.2 * n(rng), 0.3 + 0.2 * n(rng));
    const Vector3d accel(n(rng), n(rng), 9.8 + 0.3 * n(rng));
    const double dt = 0.005 + 0.01 * u(rng);
    for (LeftInekf* f : {&deferred, &per_step, &unread}) f->propagate(gyro, accel, dt);
    if (u(rng) < 0.3) static_cast<void>(deferred.covariance());
    if (u(rng) < 0.1) {
      const NavState x = per_step.state();
      const Vector3d y = x.position + x.rotation * lever + 0.3 * Vector3d(n(rng), n(rng), n(rng));
      const Matrix3d noise = Matrix3d::Identity() * 0.09;
      const CorrectionResult a = deferred.correct_position(y, noise, lever, gate2);
      const CorrectionResult b = per_step.correct_position(y, noise, lever, gate2);
      unread.correct_position(y, noise, lever, gate2);
      ASSERT_EQ(a.accepted, b.accepted);
      EXPECT_NEAR(a.mahalanobis2, b.mahalanobis2, 1e-9 * b.mahalanobis2);
      EXPECT_LT(relative_difference(deferred.covariance(), per_step.covariance()), 1e-9)
          << "step " << k;
      if (u(rng) < 0.3) {
        const Vector3d vel = x.velocity + 0.1 * Vector3d(n(rng), n(rng), n(rng));
        for (LeftInekf* f : {&deferred, &per_step, &unread}) {
          f->correct_velocity(vel, Matrix3d::Identity() * 0.01, gate2);
        }
      }
    }
  }
  const Vector15 e = deferred.error_from(per_step.state());
  EXPECT_LT(e.norm(), 1e-9);
  EXPECT_LT(relative_difference(deferred.covariance(), per_step.covariance()), 1e-9);
  // Reading the covariance caches it but leaves the filter's arithmetic alone.
  EXPECT_TRUE(identical(deferred.state(), unread.state()));
  EXPECT_TRUE(deferred.covariance() == unread.covariance());
}

TEST(LeftInekf, GatesFiftyMetreJumpAndAcceptsConsistentFix) {
  FilterParams params;
  LeftInekf f(params);
  Matrix15 p = Matrix15::Identity() * 1e-4;
  p.block<3, 3>(kPos, kPos) = Matrix3d::Identity();
  f.reset(some_state(), p);
  const double gate2 = chi_square_quantile(0.999, 3);
  const Matrix3d n = Matrix3d::Identity();
  const Vector3d lever(0.5, 0.0, 1.2);
  const NavState before = f.state();
  const Vector3d antenna = before.position + before.rotation * lever;

  const CorrectionResult jump = f.correct_position(antenna + Vector3d(50.0, 0, 0), n, lever, gate2);
  EXPECT_FALSE(jump.accepted);
  EXPECT_GT(jump.mahalanobis2, gate2);
  EXPECT_LT((f.state().position - before.position).norm(), 1e-15);

  const CorrectionResult ok = f.correct_position(antenna + Vector3d(1.0, 0, 0), n, lever, gate2);
  EXPECT_TRUE(ok.accepted);
  // Equal prior and measurement variance: the estimate moves about half way.
  EXPECT_NEAR(f.state().position.x() - before.position.x(), 0.5, 0.05);
  EXPECT_LT(f.covariance()(kPos, kPos), p(kPos, kPos) * 0.6);
}

TEST(LeftInekf, CovarianceStaysSymmetricPositiveDefinite) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  FilterParams params;
  LeftInekf f(params);
  f.reset(some_state(), Matrix15::Identity() * 0.01);
  const double gate2 = chi_square_quantile(0.999, 3);
  for (int k = 0; k < 20000; ++k) {
    f.propagate(Vector3d(0.1 * n(rng), 0.1 * n(rng), 0.3), Vector3d(0.2, 0.1, 9.81), 0.01);
    if (k % 10 == 0) {
      const Vector3d y = f.state().position + 0.01 * Vector3d(n(rng), n(rng), n(rng));
      f.correct_position(y, Matrix3d::Identity() * 1e-4, Vector3d::Zero(), gate2);
      f.correct_velocity(f.state().velocity, Matrix3d::Identity() * 1e-2, gate2);
    }
  }
  const Matrix15 p = f.covariance();
  EXPECT_LT((p - p.transpose()).norm(), 1e-15 * p.norm());
  Eigen::SelfAdjointEigenSolver<Matrix15> es(p);
  EXPECT_GT(es.eigenvalues().minCoeff(), 0.0);
  EXPECT_TRUE(f.state().rotation.allFinite());
  EXPECT_LT((f.state().rotation.transpose() * f.state().rotation - Matrix3d::Identity()).norm(),
            1e-12);
}

}  // namespace
}  // namespace semap::estimation
