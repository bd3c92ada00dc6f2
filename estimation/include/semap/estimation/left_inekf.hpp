#pragma once

#include <Eigen/Core>

#include "semap/estimation/filter_params.hpp"
#include "semap/estimation/nav_filter.hpp"

namespace semap::estimation {

// Blocks of the discrete transition Phi = expm(A dt) of the left-invariant error. Row/column
// blocks are [rot, vel, pos, gyro bias, accel bias]; blocks not listed are 0 (or I on the
// bias diagonal), and Phi_11 = Phi_22 = Phi_33 = omega, Phi_32 = omega dt.
struct LeftInekfTransition {
  Eigen::Matrix3d omega;  // Gamma0(w dt)^T
  Eigen::Matrix3d f21, f31, f14, f24, f25, f34, f35;
  Eigen::Vector3d u1, u2;  // Gamma1(w dt) a dt and Gamma2(w dt) a dt^2 (the state increments)
  double dt = 0.0;

  // The transition for bias-corrected rates w and accelerations a held over dt.
  static LeftInekfTransition compute(const Eigen::Vector3d& w, const Eigen::Vector3d& a, double dt);
  Matrix15 dense() const;
};

// Left-invariant EKF on SE_2(3) x R^6 (Hartley et al.; Barrau & Bonnabel).
//
// Error convention: xi = log(X_hat^-1 X) for the group part and zeta = theta - theta_hat for
// the biases, so X = X_hat exp(xi). This is the negative of eta = X^-1 X_hat used in the
// issue; the linear error dynamics A and the covariance are identical for both signs.
//
// Propagation uses the closed-form Gamma functions; Phi is closed form except the two gyro
// bias couplings into velocity and position, which are integrals of rotation functions and
// are evaluated with 3-point Gauss-Legendre (exact to degree 5 in dt, fixed-size work).
class LeftInekf final : public NavFilter {
 public:
  explicit LeftInekf(const FilterParams& params);

  void reset(const NavState& state, const Matrix15& world_covariance) override;
  void propagate(const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel, double dt) override;
  CorrectionResult correct_position(const Eigen::Vector3d& position,
                                    const Eigen::Matrix3d& covariance,
                                    const Eigen::Vector3d& lever_arm, double gate2) override;
  CorrectionResult correct_velocity(const Eigen::Vector3d& velocity,
                                    const Eigen::Matrix3d& covariance, double gate2) override;

  void inflate(const Eigen::Matrix3d& position_covariance,
               const Eigen::Matrix3d& velocity_covariance) override;

  NavState state() const override;
  const Matrix15& covariance() const override { return p_; }
  Vector15 error_from(const NavState& truth) const override;
  Eigen::Matrix3d rotation_covariance_world() const override;
  Eigen::Matrix3d position_covariance_world() const override;

 private:
  void apply_transition(const LeftInekfTransition& phi);
  void retract(const Vector15& delta);

  FilterParams params_;
  Eigen::Matrix<double, 15, 1> q_diag_;  // continuous process noise densities squared
  Eigen::Matrix3d r_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d v_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_pos_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d bg_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d ba_ = Eigen::Vector3d::Zero();
  Matrix15 p_ = Matrix15::Identity();
  unsigned steps_since_normalise_ = 0;
};

// Diagonal of the continuous process noise Q shared by both filters.
Eigen::Matrix<double, 15, 1> process_noise_diagonal(const ImuNoise& noise);

}  // namespace semap::estimation
