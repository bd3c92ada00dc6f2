#include "semap/estimation/left_inekf.hpp"

#include <Eigen/Geometry>

#include "semap/estimation/kalman_update.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;
using PaddedBlock9 = LeftInekf::PaddedBlock9;
using PaddedBlock6 = LeftInekf::PaddedBlock6;

// Orthonormality drifts by ~1e-16 per step; re-projecting every few hundred steps is enough.
constexpr unsigned kNormaliseEvery = 256;

// Distance from the covariance origin beyond which it is moved to the robot (see header).
constexpr double kMaxOriginDistance = 100.0;

// Left-multiplies the rot/vel/pos row blocks of m by the gravity shear
// F = [[I, 0, 0], [[g]x dt, I, 0], [[g]x dt^2/2, I dt, I]].
template <typename M>
void shear_rows(M& m, const Vector3d& g, double dt) {
  for (int c = 0; c < m.cols(); ++c) {
    const Vector3d gr = dt * g.cross(Vector3d(m.template block<3, 1>(kRot, c)));
    m.template block<3, 1>(kPos, c) += dt * m.template block<3, 1>(kVel, c) + (0.5 * dt) * gr;
    m.template block<3, 1>(kVel, c) += gr;
  }
}

// Right-multiplies the 9 columns of m by F^T, as whole-column AXPYs ([g]x has a zero
// diagonal, so each column takes two rotation columns).
void shear_columns(PaddedBlock9& m, const Vector3d& g, double dt) {
  const Matrix3d d1 = dt * skew(g);
  const Matrix3d d2 = (0.5 * dt) * d1;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const int k = (i + 2) % 3;
    m.col(kPos + i) +=
        dt * m.col(kVel + i) + d2(i, j) * m.col(kRot + j) + d2(i, k) * m.col(kRot + k);
    m.col(kVel + i) += d1(i, j) * m.col(kRot + j) + d1(i, k) * m.col(kRot + k);
  }
}

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

Eigen::Matrix<double, 15, 1> process_noise_diagonal(const ImuNoise& noise) {
  Eigen::Matrix<double, 15, 1> q;
  q.segment<3>(kRot).setConstant(noise.gyro_noise * noise.gyro_noise);
  q.segment<3>(kVel).setConstant(noise.accel_noise * noise.accel_noise);
  q.segment<3>(kPos).setConstant(noise.position_process * noise.position_process);
  q.segment<3>(kGyroBias).setConstant(noise.gyro_bias_walk * noise.gyro_bias_walk);
  q.segment<3>(kAccelBias).setConstant(noise.accel_bias_walk * noise.accel_bias_walk);
  return q;
}

LeftInekf::LeftInekf(const FilterParams& params)
    : params_(params), q_diag_(process_noise_diagonal(params.noise)) {}

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
  set_world_covariance(to_world * world_covariance * to_world.transpose());
  steps_since_normalise_ = 0;
}

void LeftInekf::add_process_noise(double dt) {
  // P_w += Ad_X (Q dt) Ad_X^T for the isotropic blocks of Q, in closed form with
  // [v]x [v]x^T = |v|^2 I - v v^T and [p]x [v]x^T = (p.v) I - v p^T.
  const double qg = q_diag_(kRot) * dt;
  const double qa = q_diag_(kVel) * dt;
  const double qp = q_diag_(kPos) * dt;
  const Vector3d p = p_pos_ - origin_;
  const Matrix3d vx = qg * skew(v_);
  const Matrix3d px = qg * skew(p);
  auto a = a_.topRows<9>();
  a.block<3, 3>(kRot, kRot).diagonal().array() += qg;
  a.block<3, 3>(kVel, kRot) += vx;
  a.block<3, 3>(kRot, kVel) -= vx;
  a.block<3, 3>(kPos, kRot) += px;
  a.block<3, 3>(kRot, kPos) -= px;
  Matrix3d vv = -qg * v_ * v_.transpose();
  vv.diagonal().array() += qg * v_.squaredNorm() + qa;
  a.block<3, 3>(kVel, kVel) += vv;
  Matrix3d pv = -qg * v_ * p.transpose();
  pv.diagonal().array() += qg * p.dot(v_);
  a.block<3, 3>(kPos, kVel) += pv;
  a.block<3, 3>(kVel, kPos) += pv.transpose();
  Matrix3d pp = -qg * p * p.transpose();
  pp.diagonal().array() += qg * p.squaredNorm() + qp;
  a.block<3, 3>(kPos, kPos) += pp;
  c_.diagonal() += q_diag_.tail<6>() * dt;
}

void LeftInekf::apply_step(const InekfImuStep& step) {
  // Phi = [[F, G], [0, I]] on P = [[A, B], [B^T, C]] gives
  //   B+ = F B + G C,  A+ = F A F^T + W G^T + G W^T with W = F B + G C / 2,  C+ = C.
  // The blocks are kept with a zero tenth row so that every column is whole SIMD packets.
  const Vector3d& g = params_.gravity;
  const double dt = step.dt;
  const PaddedBlock6& gmat = step.bias_coupling;
  PaddedBlock6 fb = b_;
  shear_rows(fb, g, dt);
  PaddedBlock6 gc;
  gc.noalias() = gmat.lazyProduct(c_);
  b_ = fb + gc;
  const PaddedBlock6 w = fb + 0.5 * gc;
  PaddedBlock9 wg;  // W G^T; the rotation rows of G have no accel-bias part
  wg.leftCols<3>().noalias() = w.leftCols<3>().lazyProduct(gmat.block<3, 3>(kRot, 0).transpose());
  wg.rightCols<6>().noalias() = w.lazyProduct(gmat.middleRows<6>(kVel).transpose());
  shear_rows(a_, g, dt);  // F A, then F A F^T
  shear_columns(a_, g, dt);
  a_ += wg;
  a_.topRows<9>() += wg.topRows<9>().transpose();
}

void LeftInekf::propagate(const Vector3d& gyro, const Vector3d& accel, double dt) {
  const Vector3d w = gyro - bg_;
  const Vector3d a = accel - ba_;
  const Vector3d& g = params_.gravity;
  // P- = Phi (P + Q dt) Phi^T
  add_process_noise(dt);
  const InekfImuStep step = InekfImuStep::compute(r_, v_, p_pos_ - origin_, w, a, dt, g);
  apply_step(step);

  p_pos_ += v_ * dt + r_ * step.u2 + (0.5 * dt * dt) * g;
  v_ += r_ * step.u1 + dt * g;
  r_ = r_ * step.rotation_increment;
  if (++steps_since_normalise_ >= kNormaliseEvery) {
    r_ = Eigen::Quaterniond(r_).normalized().toRotationMatrix();
    steps_since_normalise_ = 0;
  }
  // Without fixes (outage, dead reckoning) the robot drifts away from the origin; follow it.
  if ((p_pos_ - origin_).squaredNorm() > kMaxOriginDistance * kMaxOriginDistance) {
    move_origin(Matrix3d::Identity(), Vector3d::Zero(), Vector3d::Zero());
  }
}

void LeftInekf::move_origin(const Matrix3d& e, const Vector3d& dv, const Vector3d& dp) {
  // Re-expressing xi_o at origin o' = p is the adjoint of the pure translation (I, 0, o - o'),
  // composed here with Ad_E of a correction: (e, dv, dp + o - o').
  const Vector3d shift = origin_ - p_pos_;
  origin_ = p_pos_;
  const Vector3d dp_shifted = dp + shift;
  Matrix9 ad_a = a_.topRows<9>();
  apply_adjoint(ad_a, e, dv, dp_shifted);
  Eigen::Matrix<double, 9, 6> ad_b = b_.topRows<9>();
  apply_adjoint(ad_b, e, dv, dp_shifted);
  b_.topRows<9>() = ad_b;
  Matrix9 a = ad_a.transpose();
  apply_adjoint(a, e, dv, dp_shifted);
  a_.topRows<9>() = a;
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

CorrectionResult LeftInekf::update_world(const Vector3d& residual, const Matrix3x15& h,
                                         const Matrix3d& noise, double gate2) {
  CorrectionResult out;
  out.residual = residual;
  Matrix15 p = world_covariance();
  const KalmanUpdate u = joseph_update(p, residual, h, noise, gate2);
  out.accepted = u.accepted;
  out.mahalanobis2 = u.mahalanobis2;
  if (u.accepted) {
    set_world_covariance(p);
    correct_world(u.delta);
  }
  return out;
}

void LeftInekf::inflate(const Matrix3d& position_covariance, const Matrix3d& velocity_covariance) {
  // World-frame position and velocity errors are exactly the vel/pos blocks of xi_w.
  a_.block<3, 3>(kPos, kPos) += position_covariance;
  a_.block<3, 3>(kVel, kVel) += velocity_covariance;
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
  const Matrix15 p = t * world_covariance() * t.transpose();
  return 0.5 * (p + p.transpose());
}

Matrix15 LeftInekf::world_covariance() const {
  Matrix15 p;
  p.topLeftCorner<9, 9>() = a_.topRows<9>();
  p.topRightCorner<9, 6>() = b_.topRows<9>();
  p.bottomLeftCorner<6, 9>() = b_.topRows<9>().transpose();
  p.bottomRightCorner<6, 6>() = c_;
  return p;
}

void LeftInekf::set_world_covariance(const Matrix15& p) {
  a_.topRows<9>() = p.topLeftCorner<9, 9>();
  a_.row(9).setZero();
  b_.topRows<9>() = p.topRightCorner<9, 6>();
  b_.row(9).setZero();
  c_ = p.bottomRightCorner<6, 6>();
}

Eigen::Matrix3d LeftInekf::rotation_covariance_world() const { return a_.block<3, 3>(kRot, kRot); }

Eigen::Matrix3d LeftInekf::position_covariance_world() const {
  // R xi_p = rho_p - [p - o]x phi.
  Eigen::Matrix<double, 3, 9> l = Eigen::Matrix<double, 3, 9>::Zero();
  l.block<3, 3>(0, kRot) = -skew(p_pos_ - origin_);
  l.block<3, 3>(0, kPos).setIdentity();
  return l * a_.topRows<9>() * l.transpose();
}

}  // namespace semap::estimation
