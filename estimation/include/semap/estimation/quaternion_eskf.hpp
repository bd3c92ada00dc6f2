#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "semap/estimation/filter_params.hpp"
#include "semap/estimation/nav_filter.hpp"

namespace semap::estimation {

// Conventional quaternion error-state EKF (Sola, "Quaternion kinematics for the error-state
// Kalman filter"), the baseline the InEKF is compared against. Error: local rotation
// dtheta (R = R_hat Exp(dtheta)), world-frame velocity and position, additive biases.
// First-order discrete transition, Joseph update, reset Jacobian after injection.
class QuaternionEskf final : public NavFilter {
 public:
  explicit QuaternionEskf(const FilterParams& params);

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
  Matrix15 covariance() const override { return p_; }
  Vector15 error_from(const NavState& truth) const override;
  Eigen::Matrix3d rotation_covariance_world() const override;
  Eigen::Matrix3d position_covariance_world() const override;

 private:
  void inject(const Vector15& delta);

  FilterParams params_;
  Vector15 q_diag_;          // Q, with the velocity block in accel_q_ instead
  Eigen::Vector3d accel_q_;  // body-frame accel noise densities squared
  Eigen::Quaterniond q_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d v_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_pos_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d bg_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d ba_ = Eigen::Vector3d::Zero();
  Matrix15 p_ = Matrix15::Identity();
};

}  // namespace semap::estimation
