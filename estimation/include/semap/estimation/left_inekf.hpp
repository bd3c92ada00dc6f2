#pragma once

#include <Eigen/Core>

#include "semap/estimation/filter_params.hpp"
#include "semap/estimation/inekf_imu_step.hpp"
#include "semap/estimation/kalman_update.hpp"
#include "semap/estimation/nav_filter.hpp"

namespace semap::estimation {

// Left-invariant EKF on SE_2(3) x R^6 (Hartley et al.; Barrau & Bonnabel).
//
// Error convention: xi = log(X_hat^-1 X) for the group part and zeta = theta - theta_hat for
// the biases, so X = X_hat exp(xi). This is the negative of eta = X^-1 X_hat used in the
// issue; the linear error dynamics A and the covariance are identical for both signs.
//
// The covariance is stored for the world-aligned form of that same error, xi_w = Ad_X xi
// (X = exp(xi_w) X_hat), where the group part of the transition is a constant gravity shear
// (see InekfImuStep): propagation then costs a few 9x6 products instead of two 15x15 ones.
// Positions in Ad_X are taken relative to an origin o kept near the robot (moved to it at
// every correction and after 100 m without one): with o fixed far away, [p]x terms of size
// |p|^2 var(rot) would cancel in the left covariance and cost digits.
// Corrections use H and the innovation in world form and re-express the covariance at the
// corrected state, so the filter computes exactly the left-invariant EKF; covariance()
// returns the left-invariant covariance.
class LeftInekf final : public NavFilter {
 public:
  // Covariance blocks with a zero tenth row, so that every column is whole SIMD packets.
  using PaddedBlock9 = Eigen::Matrix<double, 10, 9>;
  using PaddedBlock6 = Eigen::Matrix<double, 10, 6>;

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
  Matrix15 covariance() const override;
  Vector15 error_from(const NavState& truth) const override;
  Eigen::Matrix3d rotation_covariance_world() const override;
  Eigen::Matrix3d position_covariance_world() const override;

 private:
  void add_process_noise(double dt);
  void apply_step(const InekfImuStep& step);
  // Gated Joseph update of the world-form covariance with a world-form residual and H; on
  // acceptance corrects the state.
  CorrectionResult update_world(const Eigen::Vector3d& residual, const Matrix3x15& h,
                                const Eigen::Matrix3d& noise, double gate2);
  // X+ = exp(delta) X for a world-form correction delta (= X exp(Ad_X^-1 delta)).
  void correct_world(const Vector15& delta);
  // Moves the origin to the current position, re-expressing the covariance through
  // Ad_E (E = (e, dv, dp): identity when only moving) combined with the translation.
  void move_origin(const Eigen::Matrix3d& e, const Eigen::Vector3d& dv, const Eigen::Vector3d& dp);
  NavState relative_state() const;  // the state with positions relative to origin_
  Matrix15 world_covariance() const;
  void set_world_covariance(const Matrix15& p);

  FilterParams params_;
  Eigen::Matrix<double, 15, 1> q_diag_;  // continuous process noise densities squared
  Eigen::Matrix3d r_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d v_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_pos_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // of the covariance's world form
  Eigen::Vector3d bg_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d ba_ = Eigen::Vector3d::Zero();
  // Covariance of (xi_w, zeta) as [[A, B], [B^T, C]]: A over rot/vel/pos, C over the biases.
  PaddedBlock9 a_ = PaddedBlock9::Identity();
  PaddedBlock6 b_ = PaddedBlock6::Zero();
  Eigen::Matrix<double, 6, 6> c_ = Eigen::Matrix<double, 6, 6>::Identity();
  unsigned steps_since_normalise_ = 0;
};

// Diagonal of the continuous process noise Q shared by both filters.
Eigen::Matrix<double, 15, 1> process_noise_diagonal(const ImuNoise& noise);

}  // namespace semap::estimation
