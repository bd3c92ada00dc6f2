#include "semap/estimation/covariance_window.hpp"

#include <Eigen/Geometry>
#include <cmath>

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

// Column c of y += n n.row(c)^T + hq h.row(c)^T over its first Rows rows (and the first
// Ranks columns of h), as one chain of FMAs on whole packets per packet of rows (a lazy
// product per term would cost a multiply and an add more per packet).
template <int Rows, int Ranks>
void add_outer_column(PaddedBlock9& y, const GyroNoiseFactor& n, const PaddedBlock6& hq,
                      const PaddedBlock6& h, int c) {
  Eigen::Matrix<double, Rows, 1> acc = y.col(c).template head<Rows>();
  for (int k = 0; k < 3; ++k) acc += n.col(k).template head<Rows>() * n(c, k);
  for (int k = 0; k < Ranks; ++k) acc += hq.col(k).template head<Rows>() * h(c, k);
  y.col(c).template head<Rows>() = acc;
}

// a.block<3, 3>(row, col) += sign S for the symmetric S in row `power` of the accel sums (see
// the header).
void add_accel_sum(PaddedBlock9& a, const Eigen::Matrix<double, 4, 6>& sums, int power, int row,
                   int col, double sign) {
  int e = 0;
  for (int j = 0; j < 3; ++j) {
    a(row + j, col + j) += sign * sums(power, e++);
    for (int i = j + 1; i < 3; ++i, ++e) {
      a(row + i, col + j) += sign * sums(power, e);
      a(row + j, col + i) += sign * sums(power, e);
    }
  }
}

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
      gyro_sigma_(noise.gyro_noise),
      accel_sigma_(noise.accel_noise),
      qp_(noise.position_process * noise.position_process) {
  qb_ << noise.gyro_bias_walk.cwiseAbs2(), noise.accel_bias_walk.cwiseAbs2();
}

void CovarianceWindow::clear() {
  steps_ = 0;
  elapsed_ = 0.0;
  h_.setZero();
  kq_.setZero();
  y_.setZero();
  accel_sums_.setZero();
}

void CovarianceWindow::add(const InekfImuStep& step, const Matrix3d& r) {
  const double dt = step.dt;
  if (dt != scaled_dt_) {
    scaled_dt_ = dt;
    const double root_dt = std::sqrt(dt);
    gyro_scale_ = root_dt * gyro_sigma_;
    accel_scale_ = root_dt * accel_sigma_;
    bias_weights_ = qb_ * dt;
  }
  // The gyro columns of N_k, padded like H.
  const Matrix3d rg = r * gyro_scale_.asDiagonal();
  GyroNoiseFactor n;
  n.block<3, 3>(kRot, 0) = rg;
  for (int j = 0; j < 3; ++j) {
    n.block<3, 1>(kVel, j) = step.c.cross(rg.col(j));
    n.block<3, 1>(kPos, j) = step.e.cross(rg.col(j));
  }
  n.bottomRows<kPaddedRows - 9>().setZero();
  // Its accel columns [0; Ra; -t_k Ra] only need the sums of Sa, t_k Sa and t_k^2 Sa,
  // Sa = Ra Ra^T (instead of a rank-3 update of the velocity and position columns): each of
  // the 6 entries of the symmetric Sa adds to its three sums in one packet.
  const Matrix3d ra = r * accel_scale_.asDiagonal();
  const Eigen::Vector4d powers(1.0, step.t0, step.t0 * step.t0, 0.0);
  int e = 0;
  for (int j = 0; j < 3; ++j) {
    for (int i = j; i < 3; ++i) accel_sums_.col(e++) += ra.row(i).dot(ra.row(j)) * powers;
  }
  // Y += H Qb H^T dt + N N^T on the upper triangle (mirrored in apply): column c takes rows
  // 0..c rounded up to whole packets (4, 4, 4, 4, 8, 8, 8, 8, 12 rows). The rotation columns
  // have no accel-bias part (H has no rotation rows there).
  const PaddedBlock6 hq = h_ * bias_weights_.asDiagonal();
  kq_ += hq;
  for (int c = kRot; c < kRot + 3; ++c) add_outer_column<4, 3>(y_, n, hq, h_, c);
  add_outer_column<4, 6>(y_, n, hq, h_, kVel);
  for (int c = kVel + 1; c < kPos + 2; ++c) add_outer_column<8, 6>(y_, n, hq, h_, c);
  add_outer_column<kPaddedRows, 6>(y_, n, hq, h_, kPos + 2);
  h_ += step.coupling;
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
  // + Y: add_outer_column filled its upper triangle rounded up to whole packets; mirror the
  // rest.
  p.a += y_;
  for (int c = 0; c < 4; ++c) {
    for (int r = 4; r < 9; ++r) p.a(r, c) += y_(c, r);
  }
  for (int c = 4; c < 8; ++c) p.a(8, c) += y_(c, 8);
  // The accel columns of N N^T, [0, 0, 0; 0, Sa, -t_k Sa; 0, -t_k Sa, t_k^2 Sa], summed.
  add_accel_sum(p.a, accel_sums_, 0, kVel, kVel, 1.0);
  add_accel_sum(p.a, accel_sums_, 1, kPos, kVel, -1.0);
  add_accel_sum(p.a, accel_sums_, 1, kVel, kPos, -1.0);
  add_accel_sum(p.a, accel_sums_, 2, kPos, kPos, 1.0);
  shear_rows(p.a, gravity_, t);
  shear_columns(p.a, gravity_, t);
  // The position noise, isotropic and on the position block only, is left alone by F.
  p.a.block<3, 3>(kPos, kPos).diagonal().array() += qp_ * t;
  p.c = c_end;
}

}  // namespace semap::estimation
