#include "semap/estimation/left_inekf.hpp"

#include <Eigen/Geometry>
#include <array>
#include <cmath>

#include "semap/estimation/kalman_update.hpp"
#include "semap/estimation/so3.hpp"

namespace semap::estimation {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// Orthonormality drifts by ~1e-16 per step; re-projecting every few hundred steps is enough.
constexpr unsigned kNormaliseEvery = 256;

// 3-point Gauss-Legendre nodes and weights on [0, 1].
constexpr std::array<double, 3> kNodes = {0.1127016653792583, 0.5, 0.8872983346207417};
constexpr std::array<double, 3> kWeights = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};

// out (=|+=) x m^T for R x 3 column blocks, written as column AXPYs: each is a whole-column
// vector operation that Eigen vectorises (the generic small-product path stays scalar here).
template <typename Out, typename In>
void set_product(Out&& out, const In& x, const Eigen::Matrix3d& m) {
  for (int c = 0; c < 3; ++c) {
    out.col(c) = x.col(0) * m(c, 0) + x.col(1) * m(c, 1) + x.col(2) * m(c, 2);
  }
}
template <typename Out, typename In>
void add_product(Out&& out, const In& x, const Eigen::Matrix3d& m) {
  for (int c = 0; c < 3; ++c) {
    out.col(c) += x.col(0) * m(c, 0) + x.col(1) * m(c, 1) + x.col(2) * m(c, 2);
  }
}

// X Phi_top^T for X with 15 columns (R rows): block column i of the result is
// sum_j X[:, j] Phi_ij^T. R is kept even so every column is whole SIMD packets.
template <int R>
Eigen::Matrix<double, R, 9> times_phi_top_transposed(const LeftInekfTransition& b,
                                                     const Eigen::Matrix<double, R, 15>& x) {
  Eigen::Matrix<double, R, 9> out;
  const auto x1 = x.template middleCols<3>(kRot);
  const auto x2 = x.template middleCols<3>(kVel);
  const auto x3 = x.template middleCols<3>(kPos);
  const auto x4 = x.template middleCols<3>(kGyroBias);
  const auto x5 = x.template middleCols<3>(kAccelBias);
  const Eigen::Matrix<double, R, 3> x23 = b.dt * x2 + x3;
  set_product(out.template middleCols<3>(0), x1, b.omega);
  add_product(out.template middleCols<3>(0), x4, b.f14);
  set_product(out.template middleCols<3>(3), x1, b.f21);
  add_product(out.template middleCols<3>(3), x2, b.omega);
  add_product(out.template middleCols<3>(3), x4, b.f24);
  add_product(out.template middleCols<3>(3), x5, b.f25);
  set_product(out.template middleCols<3>(6), x1, b.f31);
  add_product(out.template middleCols<3>(6), x23, b.omega);
  add_product(out.template middleCols<3>(6), x4, b.f34);
  add_product(out.template middleCols<3>(6), x5, b.f35);
  return out;
}

// Upper block triangle of Y^T Phi_top^T (symmetric, = Phi_top P Phi_top^T) into p's top-left
// 9x9: block column j only for rows 0..3j+2, computed on the even-height copy y_t of Y^T.
void upper_phi_y(const LeftInekfTransition& b, const Eigen::Matrix<double, 10, 15>& y_t,
                 Matrix15& p) {
  {
    Eigen::Matrix<double, 4, 3> o;
    const auto y = y_t.topRows<4>();
    set_product(o, y.middleCols<3>(kRot), b.omega);
    add_product(o, y.middleCols<3>(kGyroBias), b.f14);
    p.block<3, 3>(0, 0) = o.topRows<3>();
  }
  {
    Eigen::Matrix<double, 6, 3> o;
    const auto y = y_t.topRows<6>();
    set_product(o, y.middleCols<3>(kRot), b.f21);
    add_product(o, y.middleCols<3>(kVel), b.omega);
    add_product(o, y.middleCols<3>(kGyroBias), b.f24);
    add_product(o, y.middleCols<3>(kAccelBias), b.f25);
    p.block<6, 3>(0, 3) = o;
  }
  {
    Eigen::Matrix<double, 10, 3> o;
    const Eigen::Matrix<double, 10, 3> y23 =
        b.dt * y_t.middleCols<3>(kVel) + y_t.middleCols<3>(kPos);
    set_product(o, y_t.middleCols<3>(kRot), b.f31);
    add_product(o, y23, b.omega);
    add_product(o, y_t.middleCols<3>(kGyroBias), b.f34);
    add_product(o, y_t.middleCols<3>(kAccelBias), b.f35);
    p.block<9, 3>(0, 6) = o.topRows<9>();
  }
  p.topLeftCorner<9, 9>().triangularView<Eigen::StrictlyLower>() =
      p.topLeftCorner<9, 9>().transpose();
}

}  // namespace

LeftInekfTransition LeftInekfTransition::compute(const Vector3d& w, const Vector3d& a, double dt) {
  LeftInekfTransition b;
  b.dt = dt;
  const Vector3d phi = w * dt;
  const auto c = gamma_coefficients(phi.norm());
  const Matrix3d k = skew(phi);
  // K^2 = phi phi^T - |phi|^2 I.
  Matrix3d k2 = phi * phi.transpose();
  k2.diagonal().array() -= phi.squaredNorm();
  const Matrix3d g1 = Matrix3d::Identity() + c.a1 * k + c.b1 * k2;
  const Matrix3d g2 = 0.5 * Matrix3d::Identity() + c.a2 * k + c.b2 * k2;
  // Gamma0^T = I - a0 K + b0 K^2 (K^T = -K).
  b.omega = Matrix3d::Identity() - c.a0 * k + c.b0 * k2;
  b.u1.noalias() = g1 * (a * dt);
  b.u2.noalias() = g2 * (a * (dt * dt));
  b.f21.noalias() = -b.omega * skew(b.u1);
  b.f31.noalias() = -b.omega * skew(b.u2);
  b.f14 = -dt * g1.transpose();  // omega Gamma1(phi) = Gamma1(-phi) = Gamma1(phi)^T
  b.f25 = b.f14;
  b.f35.noalias() = -(dt * dt) * b.omega * g2;
  // Gyro-bias couplings: Phi_24 = omega int_0^dt [e^{W s} a]x s Gamma1(w s) ds and
  // Phi_34 = omega int_0^dt (dt - s) [e^{W s} a]x s Gamma1(w s) ds.
  Matrix3d i24 = Matrix3d::Zero();
  Matrix3d i34 = Matrix3d::Zero();
  for (std::size_t n = 0; n < kNodes.size(); ++n) {
    const double s = kNodes[n] * dt;
    const Vector3d ps = w * s;
    const auto cs = gamma_coefficients(ps.norm());
    const Vector3d pa = ps.cross(a);
    const Vector3d rot_a = a + cs.a0 * pa + cs.b0 * ps.cross(pa);
    // s Gamma1(w s) = s (I + a1 [ps]x + b1 (ps ps^T - |ps|^2 I)).
    Matrix3d sg1 = (s * cs.a1) * skew(ps) + (s * cs.b1) * (ps * ps.transpose());
    sg1.diagonal().array() += s * (1.0 - cs.b1 * ps.squaredNorm());
    const Matrix3d g = skew(rot_a) * sg1;
    i24 += (kWeights[n] * dt) * g;
    i34 += (kWeights[n] * dt * (dt - s)) * g;
  }
  b.f24.noalias() = b.omega * i24;
  b.f34.noalias() = b.omega * i34;
  return b;
}

Matrix15 LeftInekfTransition::dense() const {
  Matrix15 f = Matrix15::Identity();
  f.block<3, 3>(kRot, kRot) = omega;
  f.block<3, 3>(kVel, kVel) = omega;
  f.block<3, 3>(kPos, kPos) = omega;
  f.block<3, 3>(kPos, kVel) = dt * omega;
  f.block<3, 3>(kVel, kRot) = f21;
  f.block<3, 3>(kPos, kRot) = f31;
  f.block<3, 3>(kRot, kGyroBias) = f14;
  f.block<3, 3>(kVel, kGyroBias) = f24;
  f.block<3, 3>(kVel, kAccelBias) = f25;
  f.block<3, 3>(kPos, kGyroBias) = f34;
  f.block<3, 3>(kPos, kAccelBias) = f35;
  return f;
}

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
  p_ = t * world_covariance * t.transpose();
  steps_since_normalise_ = 0;
}

void LeftInekf::apply_transition(const LeftInekfTransition& phi) {
  // With Phi = [[F, G], [0, I]] (F, G: rows 0..8), P- = Phi P Phi^T has
  //   top-right 9x6 = (P Phi_top^T)[9..14, :]^T and top-left 9x9 = Phi_top (P Phi_top^T),
  // and an unchanged bias block. Both products are formed as X Phi_top^T, on copies padded
  // to an even row count so that every column is whole SIMD packets.
  Eigen::Matrix<double, 16, 15> padded;
  padded.topRows<15>() = p_;
  padded.row(15).setZero();
  const Eigen::Matrix<double, 16, 9> y = times_phi_top_transposed<16>(phi, padded);
  Eigen::Matrix<double, 10, 15> y_t;
  y_t.topRows<9>() = y.topRows<15>().transpose();
  y_t.row(9).setZero();
  upper_phi_y(phi, y_t, p_);
  p_.bottomLeftCorner<6, 9>() = y.middleRows<6>(9);
  p_.topRightCorner<9, 6>() = y.middleRows<6>(9).transpose();
}

void LeftInekf::propagate(const Vector3d& gyro, const Vector3d& accel, double dt) {
  const Vector3d w = gyro - bg_;
  const Vector3d a = accel - ba_;
  // P- = Phi (P + Q dt) Phi^T
  p_.diagonal() += q_diag_ * dt;
  const LeftInekfTransition t = LeftInekfTransition::compute(w, a, dt);
  apply_transition(t);

  const Vector3d& g = params_.gravity;
  p_pos_ += v_ * dt + r_ * t.u2 + (0.5 * dt * dt) * g;
  v_ += r_ * t.u1 + dt * g;
  r_ = r_ * t.omega.transpose();  // R Gamma0(w dt)
  if (++steps_since_normalise_ >= kNormaliseEvery) {
    r_ = Eigen::Quaterniond(r_).normalized().toRotationMatrix();
    steps_since_normalise_ = 0;
  }
}

void LeftInekf::retract(const Vector15& delta) {
  // X+ = X exp(delta) on SE_2(3); biases are additive.
  const Vector3d phi = delta.segment<3>(kRot);
  const auto c = gamma_coefficients(phi.norm());
  const Matrix3d k = skew(phi);
  const Matrix3d k2 = k * k;
  const Matrix3d g0 = Matrix3d::Identity() + c.a0 * k + c.b0 * k2;
  const Matrix3d g1 = Matrix3d::Identity() + c.a1 * k + c.b1 * k2;
  v_ += r_ * (g1 * delta.segment<3>(kVel));
  p_pos_ += r_ * (g1 * delta.segment<3>(kPos));
  r_ = r_ * g0;
  bg_ += delta.segment<3>(kGyroBias);
  ba_ += delta.segment<3>(kAccelBias);
}

CorrectionResult LeftInekf::correct_position(const Vector3d& position, const Matrix3d& covariance,
                                             const Vector3d& lever_arm, double gate2) {
  // Y = X b with b = (lever, 0, 1): innovation X^-1 Y - b = R^T (y - p) - lever, which is
  // xi_p - [lever]x xi_R to first order, with noise R^T N R.
  CorrectionResult out;
  out.residual = position - (p_pos_ + r_ * lever_arm);
  const Vector3d z = r_.transpose() * out.residual;
  Matrix3x15 h = Matrix3x15::Zero();
  h.block<3, 3>(0, kRot) = -skew(lever_arm);
  h.block<3, 3>(0, kPos).setIdentity();
  const Matrix3d n = r_.transpose() * covariance * r_;
  const KalmanUpdate u = joseph_update(p_, z, h, n, gate2);
  out.accepted = u.accepted;
  out.mahalanobis2 = u.mahalanobis2;
  if (u.accepted) retract(u.delta);
  return out;
}

CorrectionResult LeftInekf::correct_velocity(const Vector3d& velocity, const Matrix3d& covariance,
                                             double gate2) {
  CorrectionResult out;
  out.residual = velocity - v_;
  const Vector3d z = r_.transpose() * out.residual;
  Matrix3x15 h = Matrix3x15::Zero();
  h.block<3, 3>(0, kVel).setIdentity();
  const Matrix3d n = r_.transpose() * covariance * r_;
  const KalmanUpdate u = joseph_update(p_, z, h, n, gate2);
  out.accepted = u.accepted;
  out.mahalanobis2 = u.mahalanobis2;
  if (u.accepted) retract(u.delta);
  return out;
}

void LeftInekf::inflate(const Matrix3d& position_covariance, const Matrix3d& velocity_covariance) {
  p_.block<3, 3>(kPos, kPos) += r_.transpose() * position_covariance * r_;
  p_.block<3, 3>(kVel, kVel) += r_.transpose() * velocity_covariance * r_;
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

Eigen::Matrix3d LeftInekf::rotation_covariance_world() const {
  return r_ * p_.block<3, 3>(kRot, kRot) * r_.transpose();
}

Eigen::Matrix3d LeftInekf::position_covariance_world() const {
  return r_ * p_.block<3, 3>(kPos, kPos) * r_.transpose();
}

}  // namespace semap::estimation
