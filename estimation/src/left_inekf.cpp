#include "semap/estimation/left_inekf.hpp"

#include <Eigen/Geometry>
#include <algorithm>

#include "semap/estimation/inekf_propagation.hpp"
#include "semap/estimation/kalman_update.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
// Orthonormality drifts by ~1e-16 per step; re-projecting every few hundred steps is enough.
constexpr unsigned kNormaliseEvery = 256;

// Distance from the covariance origin beyond which it is moved to the robot (see header).
constexpr double kMaxOriginDistance = 100.0;

// Longest covariance window: bounds the growth of the free-fall coordinates (g t^2 / 2) and of
// the window sums, hence their rounding, whatever the IMU rate.
constexpr double kMaxWindowSeconds = 0.32;

// Left-multiplies the rot/vel/pos row blocks of m by Ad_E for E = (e, dv, dp):
// [[e, 0, 0], [[dv]x e, e, 0], [[dp]x e, 0, e]].
template <typename M>
void apply_adjoint(M& m, const Matrix3d& e, const Vector3d& dv, const Vector3d& dp) {
  for (int c = 0; c < m.cols(); ++c) {
    const Vector3d rot = e * m.template block<3, 1>(kRot, c);
    m.template block<3, 1>(kRot, c) = rot;
    m.template block<3, 1>(kVel, c) = e * m.template block<3, 1>(kVel, c) + dv.cross(rot);
    m.template block<3, 1>(kPos, c) = e * m.template block<3, 1>(kPos, c) + dp.cross(rot);
  }
}

}  // namespace

LeftInekf::LeftInekf(const FilterParams& params, int max_window_steps)
    : params_(params),
      max_window_steps_(std::max(1, max_window_steps)),
      window_(params.noise, params.gravity) {}

void LeftInekf::reset(const NavState& state, const Matrix15& world_covariance) {
  r_ = state.rotation;
  v_ = state.velocity;
  p_pos_ = state.position;
  bg_ = state.gyro_bias;
  ba_ = state.accel_bias;
  // World-axis errors map to left-invariant ones through R^T on the three group blocks.
  Matrix15 t = Matrix15::Identity();
  for (int b = 0; b < 3; ++b) t.block<3, 3>(3 * b, 3 * b) = r_.transpose();
  origin_ = state.position;
  const Matrix15 to_world = world_from_left(relative_state()) * t;
  p_.set(to_world * world_covariance * to_world.transpose());
  window_.clear();
  cache_valid_ = false;
  steps_since_normalise_ = 0;
}

void LeftInekf::settle() {
  if (window_.empty()) return;
  if (cache_valid_) {
    p_ = cached_;
  } else {
    window_.apply(p_);
  }
  window_.clear();
  cache_valid_ = false;
}

const WorldCovariance& LeftInekf::settled() const {
  if (window_.empty()) return p_;
  if (!cache_valid_) {
    cached_ = p_;
    window_.apply(cached_);
    cache_valid_ = true;
  }
  return cached_;
}

void LeftInekf::propagate(const Vector3d& gyro, const Vector3d& accel, double dt) {
  const Vector3d w = gyro - bg_;
  const Vector3d a = accel - ba_;
  const Vector3d& g = params_.gravity;
  const InekfImuStep step =
      InekfImuStep::compute(r_, v_, p_pos_ - origin_, w, a, dt, g, window_.elapsed());
  // P- = Phi (P + Q dt) Phi^T: at once in one-step mode, else deferred, the window keeping
  // what P at its end needs.
  if (max_window_steps_ == 1) {
    p_.set(propagate_world_covariance(p_.dense(), relative_state(), step, params_));
  } else {
    window_.add(step, r_);
    cache_valid_ = false;
  }

  p_pos_ += v_ * dt + step.dp + (0.5 * dt * dt) * g;
  v_ += step.dv + dt * g;
  r_ = step.rotation;
  if (++steps_since_normalise_ >= kNormaliseEvery) {
    r_ = Eigen::Quaterniond(r_).normalized().toRotationMatrix();
    steps_since_normalise_ = 0;
  }
  if (window_.steps() >= max_window_steps_ || window_.elapsed() >= kMaxWindowSeconds) settle();
  // Without fixes (outage, dead reckoning) the robot drifts away from the origin; follow it.
  if ((p_pos_ - origin_).squaredNorm() > kMaxOriginDistance * kMaxOriginDistance) {
    settle();
    move_origin(Matrix3d::Identity(), Vector3d::Zero(), Vector3d::Zero());
  }
}

void LeftInekf::move_origin(const Matrix3d& e, const Vector3d& dv, const Vector3d& dp) {
  // Re-expressing xi_o at origin o' = p is the adjoint of the pure translation (I, 0, o - o'),
  // composed here with Ad_E of a correction: (e, dv, dp + o - o').
  const Vector3d shift = origin_ - p_pos_;
  origin_ = p_pos_;
  const Vector3d dp_shifted = dp + shift;
  Matrix9 ad_a = p_.a.topRows<9>();
  apply_adjoint(ad_a, e, dv, dp_shifted);
  Eigen::Matrix<double, 9, 6> ad_b = p_.b.topRows<9>();
  apply_adjoint(ad_b, e, dv, dp_shifted);
  p_.b.topRows<9>() = ad_b;
  Matrix9 a = ad_a.transpose();
  apply_adjoint(a, e, dv, dp_shifted);
  p_.a.topRows<9>() = a;
}

void LeftInekf::correct_world(const Vector15& delta) {
  const Vector3d phi = delta.segment<3>(kRot);
  const auto c = gamma_coefficients(phi.norm());
  const Matrix3d k = skew(phi);
  const Matrix3d k2 = k * k;
  const Matrix3d e = Matrix3d::Identity() + c.a0 * k + c.b0 * k2;
  const Matrix3d g1 = Matrix3d::Identity() + c.a1 * k + c.b1 * k2;
  const Vector3d dv = g1 * delta.segment<3>(kVel);
  const Vector3d dp = g1 * delta.segment<3>(kPos);
  r_ = e * r_;
  v_ = e * v_ + dv;
  p_pos_ = origin_ + e * (p_pos_ - origin_) + dp;
  bg_ += delta.segment<3>(kGyroBias);
  ba_ += delta.segment<3>(kAccelBias);
  // The updated covariance describes the left-invariant error at the corrected state; its
  // world form there is Ad_{X+} P Ad_{X+}^T = Ad_E P_w Ad_E^T with E = exp(delta). The origin
  // moves to the corrected position in the same transform.
  move_origin(e, dv, dp);
}

CorrectionResult LeftInekf::correct_position(const Vector3d& position, const Matrix3d& covariance,
                                             const Vector3d& lever_arm, double gate2) {
  // Y = X b with b = (lever, 0, 1). In world form the residual y - (p + R lever) is
  // rho_p - [p + R lever]x phi to first order (the left innovation R^T (y - p) - lever rotated
  // to the world), with noise N itself.
  const Vector3d antenna = p_pos_ + r_ * lever_arm;
  Matrix3x15 h = Matrix3x15::Zero();
  h.block<3, 3>(0, kRot) = -skew(antenna - origin_);
  h.block<3, 3>(0, kPos).setIdentity();
  return update_world(position - antenna, h, covariance, gate2);
}

CorrectionResult LeftInekf::correct_velocity(const Vector3d& velocity, const Matrix3d& covariance,
                                             double gate2) {
  Matrix3x15 h = Matrix3x15::Zero();
  h.block<3, 3>(0, kRot) = -skew(v_);
  h.block<3, 3>(0, kVel).setIdentity();
  return update_world(velocity - v_, h, covariance, gate2);
}

CorrectionResult LeftInekf::correct_yaw(double yaw, double variance, double gate2) {
  // (H1)-(H3), docs/estimation.md: the residual wrapped to (-pi, pi], H in world form.
  CorrectionResult out;
  if (!yaw_defined(r_)) return out;
  const double z = wrap_angle(yaw - yaw_of(r_));
  out.residual.z() = z;
  RowVector15 h = RowVector15::Zero();
  h.segment<3>(kRot) = yaw_jacobian_world(r_);
  settle();
  Matrix15 p = p_.dense();
  const KalmanUpdate u = joseph_update(p, z, h, variance, gate2);
  out.accepted = u.accepted;
  out.mahalanobis2 = u.mahalanobis2;
  if (u.accepted) {
    p_.set(p);
    correct_world(u.delta);
  }
  return out;
}

CorrectionResult LeftInekf::update_world(const Vector3d& residual, const Matrix3x15& h,
                                         const Matrix3d& noise, double gate2) {
  CorrectionResult out;
  out.residual = residual;
  settle();
  Matrix15 p = p_.dense();
  const KalmanUpdate u = joseph_update(p, residual, h, noise, gate2);
  out.accepted = u.accepted;
  out.mahalanobis2 = u.mahalanobis2;
  if (u.accepted) {
    p_.set(p);
    correct_world(u.delta);
  }
  return out;
}

void LeftInekf::inflate(const Matrix3d& position_covariance, const Matrix3d& velocity_covariance) {
  // World-frame position and velocity errors are exactly the vel/pos blocks of xi_w.
  settle();
  p_.a.block<3, 3>(kPos, kPos) += position_covariance;
  p_.a.block<3, 3>(kVel, kVel) += velocity_covariance;
}

NavState LeftInekf::state() const {
  NavState s;
  s.rotation = r_;
  s.velocity = v_;
  s.position = p_pos_;
  s.gyro_bias = bg_;
  s.accel_bias = ba_;
  return s;
}

Vector15 LeftInekf::error_from(const NavState& truth) const {
  // xi = log(X_hat^-1 X) on SE_2(3).
  Vector15 e;
  const Vector3d phi = so3_log(r_.transpose() * truth.rotation);
  const Matrix3d j_inv = gamma1_inverse(phi);
  e.segment<3>(kRot) = phi;
  e.segment<3>(kVel) = j_inv * (r_.transpose() * (truth.velocity - v_));
  e.segment<3>(kPos) = j_inv * (r_.transpose() * (truth.position - p_pos_));
  e.segment<3>(kGyroBias) = truth.gyro_bias - bg_;
  e.segment<3>(kAccelBias) = truth.accel_bias - ba_;
  return e;
}

NavState LeftInekf::relative_state() const {
  NavState s = state();
  s.position -= origin_;
  return s;
}

Matrix15 LeftInekf::covariance() const {
  const Matrix15 t = left_from_world(relative_state());
  const Matrix15 p = t * settled().dense() * t.transpose();
  return 0.5 * (p + p.transpose());
}

Eigen::Matrix3d LeftInekf::rotation_covariance_world() const {
  return settled().a.block<3, 3>(kRot, kRot);
}

Eigen::Matrix3d LeftInekf::position_covariance_world() const {
  // R xi_p = rho_p - [p - o]x phi, so the covariance is L A L^T with L = [-[p - o]x, 0, I],
  // in 3x3 blocks.
  const auto& a = settled().a;
  const Matrix3d px = skew(p_pos_ - origin_);
  const Matrix3d pa = px * a.block<3, 3>(kRot, kPos);  // [p]x A_rp
  Matrix3d out = a.block<3, 3>(kPos, kPos) - pa - pa.transpose();
  out.noalias() += px * a.block<3, 3>(kRot, kRot) * px.transpose();
  return out;
}

}  // namespace semap::estimation
