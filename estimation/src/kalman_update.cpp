#include "semap/estimation/kalman_update.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>

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

// Block column J of P += M K^T - K (P H^T)^T, rows 0..3J+2 only (the upper triangle and the
// diagonal block), as column AXPYs of fixed height.
template <int J>
void update_upper(Matrix15& p, const Matrix15x3& m, const Matrix15x3& k, const Matrix15x3& pht) {
  constexpr int kRows = 3 * J + 3;
  for (int c = 3 * J; c < 3 * J + 3; ++c) {
    p.col(c).head<kRows>() +=
        m.col(0).head<kRows>() * k(c, 0) + m.col(1).head<kRows>() * k(c, 1) +
        m.col(2).head<kRows>() * k(c, 2) - k.col(0).head<kRows>() * pht(c, 0) -
        k.col(1).head<kRows>() * pht(c, 1) - k.col(2).head<kRows>() * pht(c, 2);
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
  // S is a well-conditioned 3x3 (P block plus measurement noise): its closed-form inverse is
  // far cheaper than an LLT solve with 15 right-hand sides (Eigen's generic triangular path).
  Eigen::Matrix3d s_inv = s.inverse();
  s_inv = 0.5 * (s_inv + s_inv.transpose()).eval();
  out.mahalanobis2 = innovation.dot(s_inv * innovation);
  if (!(out.mahalanobis2 < gate2)) return out;  // also rejects NaN
  out.accepted = true;
  // K = P H^T S^-1, as column AXPYs.
  Matrix15x3 k;
  for (int c = 0; c < 3; ++c) {
    k.col(c) = pht.col(0) * s_inv(0, c) + pht.col(1) * s_inv(1, c) + pht.col(2) * s_inv(2, c);
  }
  out.delta.noalias() = k * innovation;
  // Joseph form A P A^T + K N K^T with A = I - K H, expanded through the rank-3 structure:
  // A P = P - K (P H^T)^T and A P H^T = P H^T - K S_p with S_p = H P H^T, so
  // P+ = P - K (P H^T)^T + M K^T with M = K N - A P H^T = K S - P H^T (zero up to rounding for
  // the optimal gain, which is what keeps the form robust). Updated in place.
  Matrix15x3 m = -pht;
  for (int c = 0; c < 3; ++c) {
    m.col(c) += k.col(0) * s(0, c) + k.col(1) * s(1, c) + k.col(2) * s(2, c);
  }
  // Only the upper triangle (block column j, rows 0..3j+2) is formed, then mirrored.
  update_upper<0>(covariance, m, k, pht);
  update_upper<1>(covariance, m, k, pht);
  update_upper<2>(covariance, m, k, pht);
  update_upper<3>(covariance, m, k, pht);
  update_upper<4>(covariance, m, k, pht);
  covariance.triangularView<Eigen::StrictlyLower>() = covariance.transpose();
  return out;
}

KalmanUpdate joseph_update(Matrix15& covariance, double innovation, const RowVector15& h,
                           double noise, double gate2) {
  KalmanUpdate out;
  const Vector15 pht = covariance * h.transpose();
  const double s = h.dot(pht) + noise;
  if (!(s > 0.0)) return out;
  out.mahalanobis2 = innovation * innovation / s;
  if (!(out.mahalanobis2 < gate2)) return out;  // also rejects NaN
  out.accepted = true;
  const Vector15 k = pht / s;
  out.delta = k * innovation;
  // Joseph form as above: zero m up to rounding for the optimal gain.
  const Vector15 m = k * s - pht;
  covariance.noalias() += m * k.transpose() - k * pht.transpose();
  covariance = (0.5 * (covariance + covariance.transpose())).eval();
  return out;
}

}  // namespace semap::estimation
