#include "semap/estimation/covariance_window.hpp"

#include <Eigen/Geometry>

#include "semap/estimation/so3.hpp"

namespace semap::estimation {

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// Left-multiplies the rot/vel/pos row blocks of m by the gravity shear F(t).
template <typename M>
void shear_rows(M& m, const Vector3d& g, double t) {
  for (int c = 0; c < m.cols(); ++c) {
    const Vector3d gr = t * g.cross(Vector3d(m.template block<3, 1>(kRot, c)));
    m.template block<3, 1>(kPos, c) += t * m.template block<3, 1>(kVel, c) + (0.5 * t) * gr;
    m.template block<3, 1>(kVel, c) += gr;
  }
}

// Right-multiplies the 9 columns of m by F(t)^T, as whole-column AXPYs ([g]x has a zero
// diagonal, so each column takes two rotation columns).
void shear_columns(PaddedBlock9& m, const Vector3d& g, double t) {
  const Matrix3d d1 = t * skew(g);
  const Matrix3d d2 = (0.5 * t) * d1;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const int k = (i + 2) % 3;
    m.col(kPos + i) +=
        t * m.col(kVel + i) + d2(i, j) * m.col(kRot + j) + d2(i, k) * m.col(kRot + k);
    m.col(kVel + i) += d1(i, j) * m.col(kRot + j) + d1(i, k) * m.col(kRot + k);
  }
}

// Column c of y += hq h.row(c)^T over the first Rows rows and Ranks columns of h.
template <int Rows, int Ranks>
void add_outer_column(PaddedBlock9& y, const PaddedBlock6& hq, const PaddedBlock6& h, int c) {
  // A lazy product, so that Eigen uses FMA packets (no automatic contraction in this build).
  y.col(c).template head<Rows>().noalias() += hq.template topLeftCorner<Rows, Ranks>().lazyProduct(
      h.template block<1, Ranks>(c, 0).transpose());
}

// Indices in the moment vector z = (c, e, 1, t).
constexpr int kMomentC = 0;
constexpr int kMomentE = 3;
constexpr int kMomentOne = 6;
constexpr int kMomentTime = 7;

}  // namespace

Matrix15 WorldCovariance::dense() const {
  Matrix15 p;
  p.topLeftCorner<9, 9>() = a.topRows<9>();
  p.topRightCorner<9, 6>() = b.topRows<9>();
  p.bottomLeftCorner<6, 9>() = b.topRows<9>().transpose();
  p.bottomRightCorner<6, 6>() = c;
  return p;
}

void WorldCovariance::set(const Matrix15& p) {
  a.topRows<9>() = p.topLeftCorner<9, 9>();
  a.bottomRows<kPaddedRows - 9>().setZero();
  b.topRows<9>() = p.topRightCorner<9, 6>();
  b.bottomRows<kPaddedRows - 9>().setZero();
  c = p.bottomRightCorner<6, 6>();
}

CovarianceWindow::CovarianceWindow(const ImuNoise& noise, const Vector3d& gravity)
    : gravity_(gravity),
      qg_(noise.gyro_noise * noise.gyro_noise),
      qa_(noise.accel_noise * noise.accel_noise),
      qp_(noise.position_process * noise.position_process) {
  qb_.head<3>().setConstant(noise.gyro_bias_walk * noise.gyro_bias_walk);
  qb_.tail<3>().setConstant(noise.accel_bias_walk * noise.accel_bias_walk);
}

void CovarianceWindow::clear() {
  steps_ = 0;
  elapsed_ = 0.0;
  h_.setZero();
  kq_.setZero();
  y_.setZero();
  moments_.setZero();
}

void CovarianceWindow::add(const InekfImuStep& step) {
  const double dt = step.dt;
  if (steps_ > 0) {  // H_0 = 0: the first step adds nothing to K and Y
    // Y += H Qb H^T dt on the upper block triangle (mirrored in apply): columns of block b
    // take rows 0..3b+2 rounded up to whole packets. Rotation rows have no accel-bias part.
    const Eigen::Matrix<double, 6, 1> weights = qb_ * dt;
    const PaddedBlock6 hq = h_ * weights.asDiagonal();
    kq_ += hq;
    for (int c = kRot; c < kRot + 3; ++c) add_outer_column<4, 3>(y_, hq, h_, c);
    for (int c = kVel; c < kVel + 3; ++c) add_outer_column<8, 6>(y_, hq, h_, c);
    for (int c = kPos; c < kPos + 3; ++c) add_outer_column<kPaddedRows, 6>(y_, hq, h_, c);
  }
  h_ += step.coupling;
  Eigen::Matrix<double, 8, 1> z;
  z.segment<3>(kMomentC) = step.c;
  z.segment<3>(kMomentE) = step.e;
  z(kMomentOne) = 1.0;
  z(kMomentTime) = step.t0;
  moments_.noalias() += (dt * z) * z.transpose();
  elapsed_ += dt;
  ++steps_;
}

void CovarianceWindow::apply(WorldCovariance& p) const {
  if (empty()) return;
  const double t = elapsed_;
  Eigen::Matrix<double, 6, 6> c_end = p.c;
  c_end.diagonal() += qb_ * t;
  const PaddedBlock6 u = p.b - kq_;
  PaddedBlock6 hc;
  hc.noalias() = h_.lazyProduct(c_end);
  const PaddedBlock6 w = u + 0.5 * hc;
  p.b = u + hc;
  shear_rows(p.b, gravity_, t);
  // A0 + W H^T + H W^T as two lazy products (FMA packets; a transposed add is scalar code).
  p.a.noalias() += w.lazyProduct(h_.topRows<9>().transpose());
  p.a.noalias() += h_.lazyProduct(w.topRows<9>().transpose());
  // + Y: add_outer_column filled its upper block triangle rounded up to whole packets (rows
  // 0-3 of the rotation columns, 0-7 of the velocity columns); mirror the rest.
  p.a += y_;
  for (int c = kRot; c < kRot + 3; ++c) {
    for (int r = 4; r < 9; ++r) p.a(r, c) += y_(c, r);
  }
  for (int c = kVel; c < kVel + 3; ++c) p.a(8, c) += y_(c, 8);
  shear_rows(p.a, gravity_, t);
  shear_columns(p.a, gravity_, t);
  add_white_noise(p.a);
  p.c = c_end;
}

void CovarianceWindow::add_white_noise(PaddedBlock9& a) const {
  // a_k = c_k + g T and b_k = e_k + c_k T + g h (h = T^2 / 2): their dt-weighted sums and
  // second moments expand into the moments of (c, e, 1).
  const double t = elapsed_;
  const double h = 0.5 * t * t;
  const Vector3d& g = gravity_;
  const auto m_cc = moments_.block<3, 3>(kMomentC, kMomentC);
  const auto m_ce = moments_.block<3, 3>(kMomentC, kMomentE);  // sum dt c e^T
  const auto m_ee = moments_.block<3, 3>(kMomentE, kMomentE);
  const Vector3d m_c = moments_.block<3, 1>(kMomentC, kMomentOne);
  const Vector3d m_e = moments_.block<3, 1>(kMomentE, kMomentOne);
  const double s0 = moments_(kMomentOne, kMomentOne);    // sum dt
  const double s1 = moments_(kMomentOne, kMomentTime);   // sum t_k dt
  const double s2 = moments_(kMomentTime, kMomentTime);  // sum t_k^2 dt
  const Matrix3d gg = s0 * g * g.transpose();
  const Matrix3d cg = m_c * g.transpose();
  const Matrix3d eg = m_e * g.transpose();
  const Matrix3d cg_sym = cg + cg.transpose();
  const Vector3d sum_a = m_c + (t * s0) * g;
  const Vector3d sum_b = m_e + t * m_c + (h * s0) * g;
  const Matrix3d saa = m_cc + t * cg_sym + (t * t) * gg;
  const Matrix3d sab = m_ce + t * m_cc + h * cg + t * eg.transpose() + (t * t) * cg.transpose() +
                       (t * h) * gg;  // sum dt a b^T
  const Matrix3d sbb = m_ee + t * (m_ce + m_ce.transpose()) + (t * t) * m_cc +
                       h * (eg + eg.transpose()) + (t * h) * cg_sym + (h * h) * gg;
  const double tau1 = t * s0 - s1;                     // sum tau_k dt
  const double tau2 = t * t * s0 - 2.0 * t * s1 + s2;  // sum tau_k^2 dt
  // Gyro noise qg [I; [a]x; [b]x][...]^T with [b]x [a]x^T = (a.b) I - a b^T; accel noise
  // qa [0; I; tau I][...]^T; position noise qp on the position block.
  const Matrix3d ax = qg_ * skew(sum_a);
  const Matrix3d bx = qg_ * skew(sum_b);
  a.block<3, 3>(kRot, kRot).diagonal().array() += qg_ * s0;
  a.block<3, 3>(kVel, kRot) += ax;
  a.block<3, 3>(kRot, kVel) -= ax;
  a.block<3, 3>(kPos, kRot) += bx;
  a.block<3, 3>(kRot, kPos) -= bx;
  Matrix3d vv = -qg_ * saa;
  vv.diagonal().array() += qg_ * saa.trace() + qa_ * s0;
  a.block<3, 3>(kVel, kVel) += vv;
  Matrix3d pv = -qg_ * sab;
  pv.diagonal().array() += qg_ * sab.trace() + qa_ * tau1;
  a.block<3, 3>(kPos, kVel) += pv;
  a.block<3, 3>(kVel, kPos) += pv.transpose();
  Matrix3d pp = -qg_ * sbb;
  pp.diagonal().array() += qg_ * sbb.trace() + qa_ * tau2 + qp_ * s0;
  a.block<3, 3>(kPos, kPos) += pp;
}

}  // namespace semap::estimation
