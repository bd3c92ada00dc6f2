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

// Column c of y += hq h.row(c)^T + n n.row(c)^T over the first Rows rows (and Ranks columns
// of h).
template <int Rows, int Ranks>
void add_outer_column(PaddedBlock9& y, const PaddedBlock6& hq, const PaddedBlock6& h,
                      const GyroNoiseFactor& n, int c) {
  // Lazy products, so that Eigen uses FMA packets.
  y.col(c).template head<Rows>().noalias() += hq.template topLeftCorner<Rows, Ranks>().lazyProduct(
      h.template block<1, Ranks>(c, 0).transpose());
  y.col(c).template head<Rows>().noalias() +=
      n.template topRows<Rows>().lazyProduct(n.row(c).transpose());
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
  const double root_dt = std::sqrt(dt);
  // The gyro columns of N_k, padded like H.
  const Matrix3d rg = r * (root_dt * gyro_sigma_).asDiagonal();
  GyroNoiseFactor n;
  n.block<3, 3>(kRot, 0) = rg;
  for (int j = 0; j < 3; ++j) {
    n.block<3, 1>(kVel, j) = step.c.cross(rg.col(j));
    n.block<3, 1>(kPos, j) = step.e.cross(rg.col(j));
  }
  n.bottomRows<kPaddedRows - 9>().setZero();
  // Its accel columns [0; Ra; -t_k Ra] only need the sums of Sa, t_k Sa and t_k^2 Sa,
  // Sa = Ra Ra^T (3x3 each, instead of a rank-3 update of the velocity and position columns).
  const Matrix3d ra = r * (root_dt * accel_sigma_).asDiagonal();
  Matrix3d sa;
  sa.noalias() = ra * ra.transpose();
  accel_sums_.leftCols<3>() += sa;
  accel_sums_.middleCols<3>(3) += step.t0 * sa;
  accel_sums_.rightCols<3>() += (step.t0 * step.t0) * sa;
  // Y += H Qb H^T dt + N N^T on the upper block triangle (mirrored in apply): columns of block
  // b take rows 0..3b+2 rounded up to whole packets. Rotation rows have no accel-bias part.
  const Eigen::Matrix<double, 6, 1> weights = qb_ * dt;
  const PaddedBlock6 hq = h_ * weights.asDiagonal();
  kq_ += hq;
  for (int c = kRot; c < kRot + 3; ++c) add_outer_column<4, 3>(y_, hq, h_, n, c);
  for (int c = kVel; c < kVel + 3; ++c) add_outer_column<8, 6>(y_, hq, h_, n, c);
  for (int c = kPos; c < kPos + 3; ++c) add_outer_column<kPaddedRows, 6>(y_, hq, h_, n, c);
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
  // + Y: add_outer_column filled its upper block triangle rounded up to whole packets (rows
  // 0-3 of the rotation columns, 0-7 of the velocity columns); mirror the rest.
  p.a += y_;
  for (int c = kRot; c < kRot + 3; ++c) {
    for (int r = 4; r < 9; ++r) p.a(r, c) += y_(c, r);
  }
  for (int c = kVel; c < kVel + 3; ++c) p.a(8, c) += y_(c, 8);
  // The accel columns of N N^T, [0, 0, 0; 0, Sa, -t_k Sa; 0, -t_k Sa, t_k^2 Sa], summed.
  p.a.block<3, 3>(kVel, kVel) += accel_sums_.leftCols<3>();
  p.a.block<3, 3>(kPos, kVel) -= accel_sums_.middleCols<3>(3);
  p.a.block<3, 3>(kVel, kPos) -= accel_sums_.middleCols<3>(3);
  p.a.block<3, 3>(kPos, kPos) += accel_sums_.rightCols<3>();
  shear_rows(p.a, gravity_, t);
  shear_columns(p.a, gravity_, t);
  // The position noise, isotropic and on the position block only, is left alone by F.
  p.a.block<3, 3>(kPos, kPos).diagonal().array() += qp_ * t;
  p.c = c_end;
}

}  // namespace semap::estimation
