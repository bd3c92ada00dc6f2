#pragma once

#include <Eigen/Core>

#include "semap/estimation/nav_state.hpp"

namespace semap::estimation {

// Outcome of one measurement update.
struct CorrectionResult {
  bool accepted = false;
  double mahalanobis2 = 0.0;                           // squared Mahalanobis distance
  Eigen::Vector3d residual = Eigen::Vector3d::Zero();  // measured - predicted, world frame
                                                       // (yaw: about the world z axis, rad)
};

// The interface both filters share, so the estimator front-end, the evaluation and the
// tests feed them identical inputs. Each filter keeps its own error convention; error_from()
// and covariance() are expressed in it, which is what a NEES needs.
class NavFilter {
 public:
  virtual ~NavFilter() = default;

  virtual void reset(const NavState& state, const Matrix15& covariance) = 0;
  // Zero-order hold of the raw IMU sample (body frame) over dt seconds.
  virtual void propagate(const Eigen::Vector3d& gyro, const Eigen::Vector3d& accel, double dt) = 0;
  // GNSS antenna position in the world frame, its covariance (world) and the antenna lever arm
  // (body). The update is applied only when the Mahalanobis distance is below gate2.
  virtual CorrectionResult correct_position(const Eigen::Vector3d& position,
                                            const Eigen::Matrix3d& covariance,
                                            const Eigen::Vector3d& lever_arm, double gate2) = 0;
  // Velocity of the body origin in the world frame.
  virtual CorrectionResult correct_velocity(const Eigen::Vector3d& velocity,
                                            const Eigen::Matrix3d& covariance, double gate2) = 0;
  // Yaw of the body (yaw_of: the body x axis from east, counter-clockwise, rad), e.g. from a
  // dual-antenna receiver, with its variance (rad^2); gate2 is a 1-dof chi-square bound.
  virtual CorrectionResult correct_yaw(double yaw, double variance, double gate2) = 0;

  // Adds world-frame covariances to the position and velocity uncertainty (recovery from a
  // filter that has become overconfident and gates out every fix).
  virtual void inflate(const Eigen::Matrix3d& position_covariance,
                       const Eigen::Matrix3d& velocity_covariance) = 0;

  virtual NavState state() const = 0;
  virtual Matrix15 covariance() const = 0;
  // Error of this estimate with respect to `truth` in the filter's own error coordinates.
  virtual Vector15 error_from(const NavState& truth) const = 0;
  // Covariance of rotation (world axes, rad^2) and position (world, m^2) for reporting.
  virtual Eigen::Matrix3d rotation_covariance_world() const = 0;
  virtual Eigen::Matrix3d position_covariance_world() const = 0;
};

}  // namespace semap::estimation
