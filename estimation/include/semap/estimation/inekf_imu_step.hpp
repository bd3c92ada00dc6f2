#pragma once

#include <Eigen/Core>

#include "semap/estimation/nav_state.hpp"

namespace semap::estimation {

using Matrix9 = Eigen::Matrix<double, 9, 9>;
// Blocks of the world-form covariance padded with zero rows to 12, so that every column is
// three whole AVX packets (with 10 rows Eigen falls back to SSE packets).
inline constexpr int kPaddedRows = 12;
using PaddedBlock9 = Eigen::Matrix<double, kPaddedRows, 9>;
using PaddedBlock6 = Eigen::Matrix<double, kPaddedRows, 6>;

// Adjoint of X = (R, v, p) in SE_2(3): exp(Ad_X xi) X = X exp(xi).
Matrix9 se23_adjoint(const Eigen::Matrix3d& r, const Eigen::Vector3d& v, const Eigen::Vector3d& p);

// blockdiag(Ad_X, I_6) and its inverse for X = `state`: they map a left-invariant error xi
// (X_true = X exp(xi)) to its world-aligned form xi_w = Ad_X xi (X_true = exp(xi_w) X) and back,
// so P_w = T P T^T.
Matrix15 world_from_left(const NavState& state);
Matrix15 left_from_world(const NavState& state);

// The gravity shear F(t) = [[I, 0, 0], [[g]x t, I, 0], [[g]x t^2 / 2, I t, I]]: the group block
// of the world-form error transition over any t, whatever the motion; F(s) F(t) = F(s + t).
Matrix9 gravity_shear(const Eigen::Vector3d& gravity, double t);

// One zero-order-hold IMU step of the Left-InEKF from (R, v, p) with bias-corrected rate w
// and specific force a over dt:
//   R+ = R Gamma0(w dt),  v+ = v + R Gamma1 a dt + g dt,  p+ = p + v dt + R Gamma2 a dt^2 + g
//   dt^2/2.
// Its error transition for world-aligned errors xi_w = Ad_X xi (Phi_w = T(X+) Phi T(X)^-1) is
// [[F(dt), G], [0, I]]: only the 9x6 coupling G to the bias errors depends on the motion.
//
// The step is taken at time t0 of a covariance window (see CovarianceWindow) and gives G
// referred to the window start, F(-t1) G with t1 = t0 + dt: products of such steps then add
// up instead of shearing each other. In those coordinates gravity drops out: G depends on the
// state only through the free-fall coordinates c = v - g t0 and e = p - v t0 + g t0^2 / 2,
// which also carry the process noise of the step to the end of the window.
struct InekfImuStep {
  Eigen::Matrix3d rotation;  // R+
  Eigen::Vector3d dv, dp;    // R Gamma1 a dt and R Gamma2 a dt^2 (world, without gravity)
  Eigen::Vector3d c, e;      // free-fall velocity and position at the start of the step
  // F(-t1) G (rows: rot, vel, pos errors, then zero padding; columns: gyro, accel bias
  // errors).
  PaddedBlock6 coupling;
  double dt = 0.0;
  double t0 = 0.0;

  static InekfImuStep compute(const Eigen::Matrix3d& r, const Eigen::Vector3d& v,
                              const Eigen::Vector3d& p, const Eigen::Vector3d& w,
                              const Eigen::Vector3d& a, double dt, const Eigen::Vector3d& gravity,
                              double t0 = 0.0);

  // The full 15x15 Phi_w of this step (G = F(t1) coupling), for tests and diagnostics.
  Matrix15 dense(const Eigen::Vector3d& gravity) const;
};

}  // namespace semap::estimation
