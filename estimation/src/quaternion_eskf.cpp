#include "semap/estimation/quaternion_eskf.hpp"

#include "semap/estimation/kalman_update.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {

namespace {
using Eigen::Matrix3d;
using Eigen::Vector3d;

Eigen::Quaterniond quaternion_exp(const Vector3d& phi) { return Eigen::Quaterniond(gamma0(phi)); }
}  // namespace

QuaternionEskf::QuaternionEskf(const FilterParams& params)
    : params_(params),
      q_diag_(process_noise_diagonal(params.noise)),
      accel_q_(q_diag_.segment<3>(kVel)) {
  q_diag_.segment<3>(kVel).setZero();
}

void QuaternionEskf::reset(const NavState& state, const Matrix15& world_covariance) {
  q_ = Eigen::Quaterniond(state.rotation).normalized();
  v_ = state.velocity;
  p_pos_ = state.position;
  bg_ = state.gyro_bias;
  ba_ = state.accel_bias;
  p_ = world_covariance;
  const Matrix3d r = q_.toRotationMatrix();
  p_.block<3, 15>(kRot, 0) = r.transpose() * p_.block<3, 15>(kRot, 0);
  p_.block<15, 3>(0, kRot) = p_.block<15, 3>(0, kRot) * r;
}

void QuaternionEskf::propagate(const Vector3d& gyro, const Vector3d& accel, double dt) {
  const Vector3d w = gyro - bg_;
  const Vector3d a = accel - ba_;
  const Matrix3d r = q_.toRotationMatrix();
  const Matrix3d dr = gamma0(w * dt);

  Matrix15 f = Matrix15::Identity();
  f.block<3, 3>(kRot, kRot) = dr.transpose();
  f.block<3, 3>(kRot, kGyroBias) = -dt * Matrix3d::Identity();
  f.block<3, 3>(kVel, kRot) = -dt * r * skew(a);
  f.block<3, 3>(kVel, kAccelBias) = -dt * r;
  f.block<3, 3>(kPos, kVel) = dt * Matrix3d::Identity();
  p_ = f * p_ * f.transpose();
  p_.diagonal() += q_diag_ * dt;
  // The velocity error is world-frame: the body-frame accel noise enters as R Qa R^T.
  p_.block<3, 3>(kVel, kVel).noalias() += r * (dt * accel_q_).asDiagonal() * r.transpose();
  p_ = 0.5 * (p_ + p_.transpose()).eval();

  const Vector3d acc_world = r * a + params_.gravity;
  p_pos_ += v_ * dt + 0.5 * dt * dt * acc_world;
  v_ += acc_world * dt;
  q_ = (q_ * quaternion_exp(w * dt)).normalized();
}

void QuaternionEskf::inject(const Vector15& delta) {
  q_ = (q_ * quaternion_exp(delta.segment<3>(kRot))).normalized();
  v_ += delta.segment<3>(kVel);
  p_pos_ += delta.segment<3>(kPos);
  bg_ += delta.segment<3>(kGyroBias);
  ba_ += delta.segment<3>(kAccelBias);
  // Reset Jacobian G = I - 1/2 [dtheta]x on the rotation block.
  Matrix15 g = Matrix15::Identity();
  g.block<3, 3>(kRot, kRot) -= 0.5 * skew(delta.segment<3>(kRot));
  p_ = g * p_ * g.transpose();
}

CorrectionResult QuaternionEskf::correct_position(const Vector3d& position,
                                                  const Matrix3d& covariance,
                                                  const Vector3d& lever_arm, double gate2) {
  CorrectionResult out;
  const Matrix3d r = q_.toRotationMatrix();
  out.residual = position - (p_pos_ + r * lever_arm);
  Matrix3x15 h = Matrix3x15::Zero();
  h.block<3, 3>(0, kRot) = -r * skew(lever_arm);
  h.block<3, 3>(0, kPos).setIdentity();
  const KalmanUpdate u = joseph_update(p_, out.residual, h, covariance, gate2);
  out.accepted = u.accepted;
  out.mahalanobis2 = u.mahalanobis2;
  if (u.accepted) inject(u.delta);
  return out;
}

CorrectionResult QuaternionEskf::correct_yaw(double yaw, double variance, double gate2) {
  // Local rotation error R = R_hat exp([dtheta]x): H is the body-axis yaw Jacobian (H2).
  CorrectionResult out;
  const Matrix3d r = q_.toRotationMatrix();
  if (!yaw_defined(r)) return out;
  const double z = wrap_angle(yaw - yaw_of(r));
  out.residual.z() = z;
  RowVector15 h = RowVector15::Zero();
  h.segment<3>(kRot) = yaw_jacobian_body(r);
  const KalmanUpdate u = joseph_update(p_, z, h, variance, gate2);
  out.accepted = u.accepted;
  out.mahalanobis2 = u.mahalanobis2;
  if (u.accepted) inject(u.delta);
  return out;
}

CorrectionResult QuaternionEskf::correct_velocity(const Vector3d& velocity,
                                                  const Matrix3d& covariance, double gate2) {
  CorrectionResult out;
  out.residual = velocity - v_;
  Matrix3x15 h = Matrix3x15::Zero();
  h.block<3, 3>(0, kVel).setIdentity();
  const KalmanUpdate u = joseph_update(p_, out.residual, h, covariance, gate2);
  out.accepted = u.accepted;
  out.mahalanobis2 = u.mahalanobis2;
  if (u.accepted) inject(u.delta);
  return out;
}

void QuaternionEskf::inflate(const Matrix3d& position_covariance,
                             const Matrix3d& velocity_covariance) {
  p_.block<3, 3>(kPos, kPos) += position_covariance;
  p_.block<3, 3>(kVel, kVel) += velocity_covariance;
}

NavState QuaternionEskf::state() const {
  NavState s;
  s.rotation = q_.toRotationMatrix();
  s.velocity = v_;
  s.position = p_pos_;
  s.gyro_bias = bg_;
  s.accel_bias = ba_;
  return s;
}

Vector15 QuaternionEskf::error_from(const NavState& truth) const {
  Vector15 e;
  e.segment<3>(kRot) = so3_log(q_.toRotationMatrix().transpose() * truth.rotation);
  e.segment<3>(kVel) = truth.velocity - v_;
  e.segment<3>(kPos) = truth.position - p_pos_;
  e.segment<3>(kGyroBias) = truth.gyro_bias - bg_;
  e.segment<3>(kAccelBias) = truth.accel_bias - ba_;
  return e;
}

Eigen::Matrix3d QuaternionEskf::rotation_covariance_world() const {
  const Matrix3d r = q_.toRotationMatrix();
  return r * p_.block<3, 3>(kRot, kRot) * r.transpose();
}

Eigen::Matrix3d QuaternionEskf::position_covariance_world() const {
  return p_.block<3, 3>(kPos, kPos);
}

}  // namespace semap::estimation
