#pragma once

#include <Eigen/Core>

#include "semap/estimation/filter_params.hpp"
#include "semap/estimation/inekf_imu_step.hpp"

namespace semap::estimation {

// Covariance of (xi_w, zeta) as [[A, B], [B^T, C]]: A over rot/vel/pos world-form errors
// (positions relative to the filter's origin), C over the biases.
struct WorldCovariance {
  PaddedBlock9 a = PaddedBlock9::Identity();
  PaddedBlock6 b = PaddedBlock6::Zero();
  Eigen::Matrix<double, 6, 6> c = Eigen::Matrix<double, 6, 6>::Identity();

  Matrix15 dense() const;
  void set(const Matrix15& p);
};

// Exact deferral of the Left-InEKF covariance propagation over a window of IMU steps.
//
// Every step k (from time t_k to t_{k+1} of the window) is P <- Phi_k (P + Qd_k) Phi_k^T with
// Phi_k = [[F(dt_k), G_k], [0, I]] in world form, F the gravity shear (F(s) F(t) = F(s + t)).
// Their product over the window is [[F(T), F(T) H], [0, I]] with H = sum_k F(-t_{k+1}) G_k,
// the couplings referred to the window start (InekfImuStep::coupling), so the window keeps
// only running sums and forms P(T) when someone needs it (apply):
//   B(T) = F(T) (B0 + H C(T) - K Qb),     C(T) = C0 + Qb T,
//   A(T) = F(T) (A0 + W H^T + H W^T + Y) F(T)^T + N(T),   W = B0 + H C(T) / 2 - K Qb,
// with K = sum_k H_{k-1} dt_k and Y = sum_k H_{k-1} Qb H_{k-1}^T dt_k (H_{k-1}: the sum before
// step k) for the bias random walk Qb injected along the window, and N(T) the white IMU noise
// carried to T. Noise injected at step k reaches T as F(tau) Ad_X Q Ad_X^T F(tau)^T dt
// (tau = T - t_k); for isotropic Q its gyro part is qg [I; [a]x; [b]x][I; [a]x; [b]x]^T dt with
// a = c_k + g T, b = e_k + c_k T + g T^2 / 2 (c, e the free-fall coordinates of the step), so
// the second moments of z_k = (c_k, e_k, 1, t_k) weighted by dt_k are all N(T) needs.
// (The white-noise part of the accel and position blocks needs sum dt, sum t_k dt and
// sum t_k^2 dt, also in those moments.) Per step that is a coupling sum, a rank-6 update of Y
// on its upper block triangle (the accel-bias columns of H have no rotation rows) and a rank-1
// update of the 8x8 moments, instead of the two 12x6 by 6x9 products, the shears and the noise
// of a per-step propagation. Noise densities must be isotropic per block (ImuNoise is).
class CovarianceWindow {
 public:
  CovarianceWindow(const ImuNoise& noise, const Eigen::Vector3d& gravity);

  bool empty() const { return steps_ == 0; }
  int steps() const { return steps_; }
  double elapsed() const { return elapsed_; }  // T, the time the next step starts at

  // Takes step k, computed with t0 = elapsed().
  void add(const InekfImuStep& step);
  // P <- P(T): the covariance at the window start, propagated over the window.
  void apply(WorldCovariance& p) const;
  void clear();

 private:
  void add_white_noise(PaddedBlock9& a) const;

  Eigen::Vector3d gravity_;
  double qg_, qa_, qp_;  // gyro, accel and position noise densities squared
  Eigen::Matrix<double, 6, 1> qb_;
  int steps_ = 0;
  double elapsed_ = 0.0;
  PaddedBlock6 h_ = PaddedBlock6::Zero();
  PaddedBlock6 kq_ = PaddedBlock6::Zero();  // K Qb
  PaddedBlock9 y_ = PaddedBlock9::Zero();
  Eigen::Matrix<double, 8, 8> moments_ = Eigen::Matrix<double, 8, 8>::Zero();
};

}  // namespace semap::estimation
