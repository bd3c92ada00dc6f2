#pragma once

#include <Eigen/Core>

namespace semap::estimation {

// Skew-symmetric matrix [v]x with [v]x u = v x u.
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

// Scalar coefficients of Gamma_0, Gamma_1 and Gamma_2 at |phi| = theta:
//   Gamma_k(phi) = g0_k I + g1_k [phi]x + g2_k [phi]x^2.
// Below theta = 0.1 the closed forms lose digits to cancellation, so a Taylor series (to
// theta^6, error < 1e-16 relative) is used there instead.
struct GammaCoefficients {
  double a0, b0;  // Gamma_0: I + a0 [phi] + b0 [phi]^2
  double a1, b1;  // Gamma_1: I + a1 [phi] + b1 [phi]^2
  double a2, b2;  // Gamma_2: 1/2 I + a2 [phi] + b2 [phi]^2
};
GammaCoefficients gamma_coefficients(double theta);

Eigen::Matrix3d gamma0(const Eigen::Vector3d& phi);  // SO(3) exponential
Eigen::Matrix3d gamma1(const Eigen::Vector3d& phi);  // left Jacobian of SO(3)
Eigen::Matrix3d gamma2(const Eigen::Vector3d& phi);

// Gamma_1(phi)^-1, used by the SE_2(3) logarithm.
Eigen::Matrix3d gamma1_inverse(const Eigen::Vector3d& phi);

// SO(3) logarithm (rotation vector), valid up to and including pi.
Eigen::Vector3d so3_log(const Eigen::Matrix3d& rotation);

// Yaw (rotation about ENU z) of a body-to-world rotation with the ZYX convention.
double yaw_of(const Eigen::Matrix3d& rotation);
// Its derivative with respect to a rotation error in body axes, R exp([phi]x):
// (0, r21, r22) / (1 - r20^2) (docs/estimation.md (H2)); undefined when the body x axis is
// vertical (r20 = +-1).
bool yaw_defined(const Eigen::Matrix3d& rotation);  // |r20| < 0.999999: pitch within ~89.9 deg
Eigen::RowVector3d yaw_jacobian_body(const Eigen::Matrix3d& rotation);
// And in world axes, exp([phi]x) R: yaw_jacobian_body(R) R^T = (e_z - r20 R e_x)^T / (1 - r20^2)
// (H3).
Eigen::RowVector3d yaw_jacobian_world(const Eigen::Matrix3d& rotation);

// Rz(yaw) Ry(pitch) Rx(roll): body (FLU) to world (ENU).
Eigen::Matrix3d rotation_from_rpy(double roll, double pitch, double yaw);

// Wraps an angle into (-pi, pi].
double wrap_angle(double angle);

}  // namespace semap::estimation
