#pragma once

#include <Eigen/Core>

#include "semap/estimation/covariance_window.hpp"
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
// (see InekfImuStep). Its propagation is the textbook P <- Phi (P + Q dt) Phi^T
// (inekf_propagation.hpp), with per-axis IMU noise. By default it is deferred exactly
// (CovarianceWindow): propagate() only accumulates running sums, and the covariance is formed
// when a correction, a query, an origin move or an inflation needs it, and at the latest
// every `max_window_steps` steps or 0.32 s, which bounds rounding and gives a long IMU-only
// run its share of the cost. With max_window_steps = 1 every step runs the textbook
// propagation itself (the reference the window is tested against).
// Queries are const and cache their result without ending the window, so the filter's output
// does not depend on who reads it when (that cache makes concurrent const reads unsafe; the
// filter has one owner thread, like Estimator).
// Positions in Ad_X are taken relative to an origin o kept near the robot (moved to it at
// every correction and after 100 m without one): with o fixed far away, [p]x terms of size
// |p|^2 var(rot) would cancel in the left covariance and cost digits.
// Corrections use H and the innovation in world form and re-express the covariance at the
// corrected state, so the filter computes exactly the left-invariant EKF; covariance()
// returns the left-invariant covariance.
class LeftInekf final : public NavFilter {
 public:
  static constexpr int kDefaultWindowSteps = 32;

  // max_window_steps = 1: the per-step textbook propagation (propagate_world_covariance).
  explicit LeftInekf(const FilterParams& params, int max_window_steps = kDefaultWindowSteps);

  void reset(const NavState& state, const Matrix15& world_covariance) override;
  void propagate(const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel, double dt) override;
  CorrectionResult correct_position(const Eigen::Vector3d& position,
                                    const Eigen::Matrix3d& covariance,
                                    const Eigen::Vector3d& lever_arm, double gate2) override;
  CorrectionResult correct_velocity(const Eigen::Vector3d& velocity,
                                    const Eigen::Matrix3d& covariance, double gate2) override;
  CorrectionResult correct_yaw(double yaw, double variance, double gate2) override;

  void inflate(const Eigen::Matrix3d& position_covariance,
               const Eigen::Matrix3d& velocity_covariance) override;

  NavState state() const override;
  Matrix15 covariance() const override;
  Vector15 error_from(const NavState& truth) const override;
  Eigen::Matrix3d rotation_covariance_world() const override;
  Eigen::Matrix3d position_covariance_world() const override;

 private:
  // Ends the covariance window: the stored covariance becomes P at the filter time.
  void settle();
  // P at the filter time, formed on demand and cached until the next propagate.
  const WorldCovariance& settled() const;
  // Gated Joseph update of the world-form covariance with a world-form residual and H; on
  // acceptance corrects the state.
  CorrectionResult update_world(const Eigen::Vector3d& residual, const Matrix3x15& h,
                                const Eigen::Matrix3d& noise, double gate2);
  // X+ = exp(delta) X for a world-form correction delta (= X exp(Ad_X^-1 delta)).
  void correct_world(const Vector15& delta);
  // Moves the origin to the current position, re-expressing the (settled) covariance through
  // Ad_E (E = (e, dv, dp): identity when only moving) combined with the translation.
  void move_origin(const Eigen::Matrix3d& e, const Eigen::Vector3d& dv, const Eigen::Vector3d& dp);
  NavState relative_state() const;  // the state with positions relative to origin_

  FilterParams params_;
  int max_window_steps_;
  Eigen::Matrix3d r_ = Eigen::Matrix3d::Identity();
  Eigen::Vector3d v_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_pos_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();  // of the covariance's world form
  Eigen::Vector3d bg_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d ba_ = Eigen::Vector3d::Zero();
  WorldCovariance p_;  // at the start of the window
  CovarianceWindow window_;
  mutable WorldCovariance cached_;  // p_ propagated over the window, valid if cache_valid_
  mutable bool cache_valid_ = false;
  unsigned steps_since_normalise_ = 0;
};

}  // namespace semap::estimation
