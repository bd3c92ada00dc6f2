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

// The gyro columns of a step's white-noise factor N_k (below), rows padded like H.
using GyroNoiseFactor = Eigen::Matrix<double, kPaddedRows, 3>;

// Exact deferral of the Left-InEKF covariance propagation over a window of IMU steps.
//
// Every step k (from time t_k to t_{k+1} of the window) is the per-step propagation of
// inekf_propagation.hpp, P <- Phi_k (P + Qd_k) Phi_k^T, with Phi_k = [[F(dt_k), G_k], [0, I]]
// in world form, F the gravity shear (F(s) F(t) = F(s + t)), and
// Qd_k = blockdiag(Ad_X Qw Ad_X^T, Qb) dt_k, Qw = diag(Qg, Qa, qp I), X = X(t_k).
// The product of the steps is [[F(T), F(T) H], [0, I]] with H = sum_k F(-t_{k+1}) G_k, the
// couplings referred to the window start (InekfImuStep::coupling), so the window keeps only
// running sums and forms P(T) when someone needs it (apply):
//   C(T) = C0 + Qb T,     B(T) = F(T) (B0 + H C(T) - K Qb),
//   A(T) = F(T) (A0 + W H^T + H W^T + Y) F(T)^T + qp T (position block),
//   W = B0 + H C(T) / 2 - K Qb,   K = sum_k H_{k-1} dt_k,
//   Y = sum_k H_{k-1} Qb H_{k-1}^T dt_k + N_k N_k^T     (H_{k-1}: the sum before step k),
// the first term for the bias random walk injected along the window, the second for the
// white IMU noise: it reaches T as F(T - t_k) Ad_X Qw Ad_X^T F(T - t_k)^T dt_k, and with
// F(T - t_k) = F(T) F(-t_k) its factor referred to the window start is
//   N_k = F(-t_k) Ad_X [Dg 0; 0 Da] sqrt(dt_k) = [R Dg, 0; [c]x R Dg, R Da; [e]x R Dg, -t_k R Da]
// (Dg, Da the diagonals of per-axis noise sigmas; c, e the free-fall coordinates of the step).
// The IMU noise is diagonal in the body frame, so its world form R D^2 R^T changes with the
// rotation of every step and has to be summed per step, exactly; only the isotropic position
// noise commutes with all of it. Per step that is a coupling sum, rank-6 (bias walk) and
// rank-3 (gyro noise) updates of Y on its upper triangle (the accel-bias columns of H have no
// rotation rows), and for the accel noise, whose columns of N_k are [0; I; -t_k I] Ra with
// Ra = R Da sqrt(dt_k), the sums of Sa, t_k Sa and t_k^2 Sa for Sa = Ra Ra^T; instead of the
// two 12x6 by 6x9 products, the shears and the noise of a per-step propagation.
class CovarianceWindow {
 public:
  CovarianceWindow(const ImuNoise& noise, const Eigen::Vector3d& gravity);

  bool empty() const { return steps_ == 0; }
  int steps() const { return steps_; }
  double elapsed() const { return elapsed_; }  // T, the time the next step starts at

  // Takes step k, computed with t0 = elapsed() from rotation r.
  void add(const InekfImuStep& step, const Eigen::Matrix3d& r);
  // P <- P(T): the covariance at the window start, propagated over the window.
  void apply(WorldCovariance& p) const;
  void clear();

 private:
  Eigen::Vector3d gravity_;
  Eigen::Vector3d gyro_sigma_, accel_sigma_;  // white noise densities per body axis
  double qp_;                                 // position noise density squared
  Eigen::Matrix<double, 6, 1> qb_;            // bias random-walk densities squared
  int steps_ = 0;
  double elapsed_ = 0.0;
  // The per-step scales of the noise for steps of length scaled_dt_: IMUs run at a fixed rate,
  // so they are computed (with a square root) only when dt changes, not per step.
  double scaled_dt_ = 0.0;
  Eigen::Vector3d gyro_scale_ = Eigen::Vector3d::Zero();   // gyro_sigma_ sqrt(dt)
  Eigen::Vector3d accel_scale_ = Eigen::Vector3d::Zero();  // accel_sigma_ sqrt(dt)
  Eigen::Matrix<double, 6, 1> bias_weights_ = Eigen::Matrix<double, 6, 1>::Zero();  // Qb dt
  PaddedBlock6 h_ = PaddedBlock6::Zero();
  PaddedBlock6 kq_ = PaddedBlock6::Zero();  // K Qb
  PaddedBlock9 y_ = PaddedBlock9::Zero();   // upper triangle, see add_outer_column
  // Sums of Sa, t_k Sa and t_k^2 Sa for the accel noise (Sa = R Da^2 R^T dt_k): rows 0-2, for
  // the 6 entries of the symmetric Sa in columns (00, 10, 20, 11, 21, 22); row 3 pads the
  // column to a whole AVX packet, so that a step adds to all three sums at once.
  Eigen::Matrix<double, 4, 6> accel_sums_ = Eigen::Matrix<double, 4, 6>::Zero();
};

}  // namespace semap::estimation
