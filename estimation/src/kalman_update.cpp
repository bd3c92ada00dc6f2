#include "semap/estimation/kalman_update.hpp"

#include <Eigen/Cholesky>

namespace semap::estimation {

KalmanUpdate joseph_update(Matrix15& covariance, const Eigen::Vector3d& innovation,
                           const Matrix3x15& h, const Eigen::Matrix3d& noise, double gate2) {
  KalmanUpdate out;
  const Eigen::Matrix<double, 15, 3> pht = covariance.lazyProduct(h.transpose());
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
  ap -= k.lazyProduct(pht.transpose());  // (I - K H) P, using H P = (P H^T)^T
  Eigen::Matrix<double, 15, 3> m = k * noise;
  m -= ap.lazyProduct(h.transpose());  // K N - A P H^T
  covariance = ap;
  covariance += m.lazyProduct(k.transpose());  // A P A^T + K N K^T
  covariance = 0.5 * (covariance + covariance.transpose()).eval();
  return out;
}

}  // namespace semap::estimation
