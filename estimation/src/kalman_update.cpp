#include "semap/estimation/kalman_update.hpp"

#include <Eigen/Cholesky>

namespace semap::estimation {

namespace {
using Matrix15x3 = Eigen::Matrix<double, 15, 3>;

// x H^T for a 15-column x, visiting only the 3x3 column blocks of H that are non-zero (a GNSS
// H has two of five), as column AXPYs that Eigen vectorises.
Matrix15x3 times_h_transposed(const Matrix15& x, const Matrix3x15& h) {
  Matrix15x3 out = Matrix15x3::Zero();
  for (int b = 0; b < 15; b += 3) {
    const auto hb = h.middleCols<3>(b);
    if (hb.isZero(0.0)) continue;
    for (int c = 0; c < 3; ++c) {
      out.col(c) += x.col(b) * hb(c, 0) + x.col(b + 1) * hb(c, 1) + x.col(b + 2) * hb(c, 2);
    }
  }
  return out;
}

// out += a b^T for 15 x 3 factors.
void add_outer(Matrix15& out, const Matrix15x3& a, const Matrix15x3& b) {
  for (int c = 0; c < 15; ++c) {
    out.col(c) += a.col(0) * b(c, 0) + a.col(1) * b(c, 1) + a.col(2) * b(c, 2);
  }
}
}  // namespace

KalmanUpdate joseph_update(Matrix15& covariance, const Eigen::Vector3d& innovation,
                           const Matrix3x15& h, const Eigen::Matrix3d& noise, double gate2) {
  KalmanUpdate out;
  const Matrix15x3 pht = times_h_transposed(covariance, h);
  const Eigen::Matrix3d s = h.lazyProduct(pht) + noise;
  const Eigen::LLT<Eigen::Matrix3d> llt(s);
  if (llt.info() != Eigen::Success) return out;
  out.mahalanobis2 = innovation.dot(llt.solve(innovation));
  if (!(out.mahalanobis2 < gate2)) return out;  // also rejects NaN
  out.accepted = true;
  // K = P H^T S^-1, with S symmetric: K^T = S^-1 (P H^T)^T.
  const Eigen::Matrix<double, 15, 3> k = llt.solve(pht.transpose()).transpose();
  out.delta.noalias() = k * innovation;
  Matrix15 ap = covariance;
  add_outer(ap, -k, pht);  // (I - K H) P, using H P = (P H^T)^T
  Eigen::Matrix<double, 15, 3> m = k * noise;
  m -= times_h_transposed(ap, h);  // K N - A P H^T
  covariance = ap;
  add_outer(covariance, m, k);  // A P A^T + K N K^T
  covariance = 0.5 * (covariance + covariance.transpose()).eval();
  return out;
}

}  // namespace semap::estimation
