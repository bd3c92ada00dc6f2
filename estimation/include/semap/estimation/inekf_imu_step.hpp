#pragma once

#include <Eigen/Core>

#include "semap/estimation/nav_state.hpp"

namespace semap::estimation {

using Matrix9 = Eigen::Matrix<double, 9, 9>;

// Adjoint of X = (R, v, p) in SE_2(3): exp(Ad_X xi) X = X exp(xi).
Matrix9 se23_adjoint(const Eigen::Matrix3d& r, const Eigen::Vector3d& v, const Eigen::Vector3d& p);

// blockdiag(Ad_X, I_6) and its inverse for X = `state`: they map a left-invariant error xi
// (X_true = X exp(xi)) to its world-aligned form xi_w = Ad_X xi (X_true = exp(xi_w) X) and back,
// so P_w = T P T^T.
Matrix15 world_from_left(const NavState& state);
Matrix15 left_from_world(const NavState& state);

// One zero-order-hold IMU step of the Left-InEKF from (R, v, p) with bias-corrected rate w
// and specific force a over dt:
//   R+ = R Gamma0(w dt),  v+ = v + R u1 + g dt,  p+ = p + v dt + R u2 + g dt^2 / 2.
// Its error transition is given for world-aligned errors xi_w = Ad_X xi, the same left-invariant
// error seen from the world (Phi_w = T(X+) Phi T(X)^-1). There the group block of Phi is the
// constant gravity shear
//   F = [[I, 0, 0], [[g]x dt, I, 0], [[g]x dt^2 / 2, I dt, I]],
// so only the 9x6 coupling G to the bias errors depends on the motion; that is what makes the
// covariance propagation cheap.
struct InekfImuStep {
  Eigen::Matrix3d rotation_increment;  // Gamma0(w dt)
  Eigen::Vector3d u1, u2;              // Gamma1(w dt) a dt and Gamma2(w dt) a dt^2
  // G (rows: rot, vel, pos errors; columns: gyro, accel bias errors), padded with a zero
  // tenth row so that every column is whole SIMD packets.
  Eigen::Matrix<double, 10, 6> bias_coupling;
  double dt = 0.0;

  static InekfImuStep compute(const Eigen::Matrix3d& r, const Eigen::Vector3d& v,
                              const Eigen::Vector3d& p, const Eigen::Vector3d& w,
                              const Eigen::Vector3d& a, double dt, const Eigen::Vector3d& gravity);

  // The full 15x15 Phi_w, for tests and diagnostics.
  Matrix15 dense(const Eigen::Vector3d& gravity) const;
};

}  // namespace semap::estimation
