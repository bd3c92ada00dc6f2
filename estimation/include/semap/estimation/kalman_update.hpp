#pragma once

#include <Eigen/Core>

#include "semap/estimation/nav_state.hpp"

namespace semap::estimation {

using Matrix3x15 = Eigen::Matrix<double, 3, 15>;
using RowVector15 = Eigen::Matrix<double, 1, 15>;

struct KalmanUpdate {
  bool accepted = false;
  double mahalanobis2 = 0.0;
  Vector15 delta = Vector15::Zero();  // error-state estimate K z (zero when gated out)
};

// Gated 3-dof Kalman update of `covariance` in Joseph form,
//   P+ = (I - K H) P (I - K H)^T + K N K^T,
// evaluated as A P A^T with A P = P - K (H P) so that no 15x15 by 15x15 product is formed.
// The innovation z is rejected (covariance untouched) when z^T S^-1 z >= gate2.
KalmanUpdate joseph_update(Matrix15& covariance, const Eigen::Vector3d& innovation,
                           const Matrix3x15& h, const Eigen::Matrix3d& noise, double gate2);

// The same for a scalar measurement (a heading): S = h P h^T + n, rejected when z^2 / S >= gate2,
// P+ = P - K (P h^T)^T + m K^T with m = K S - P h^T.
KalmanUpdate joseph_update(Matrix15& covariance, double innovation, const RowVector15& h,
                           double noise, double gate2);

}  // namespace semap::estimation
