#include "semap/estimation/so3.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

namespace semap::estimation {

namespace {
constexpr double kSeriesBelow = 0.1;

Eigen::Matrix3d combine(double c0, double c1, double c2, const Eigen::Vector3d& phi) {
  const Eigen::Matrix3d k = skew(phi);
  return c0 * Eigen::Matrix3d::Identity() + c1 * k + c2 * k * k;
}
}  // namespace

GammaCoefficients gamma_coefficients(double theta) {
  GammaCoefficients c{};
  const double t2 = theta * theta;
  if (theta < kSeriesBelow) {
    // Horner forms with reciprocal factorials: no division on the per-step path.
    const auto series = [t2](double c0, double c1, double c2, double c3) {
      return c0 - t2 * (c1 - t2 * (c2 - t2 * c3));
    };
    const double sinc = series(1.0, 1.0 / 6.0, 1.0 / 120.0, 1.0 / 5040.0);    // sin/t
    const double cosc = series(0.5, 1.0 / 24.0, 1.0 / 720.0, 1.0 / 40320.0);  // (1-cos)/t^2
    const double sinc3 =
        series(1.0 / 6.0, 1.0 / 120.0, 1.0 / 5040.0, 1.0 / 362880.0);  // (t-sin)/t^3
    const double cosc4 =
        series(1.0 / 24.0, 1.0 / 720.0, 1.0 / 40320.0, 1.0 / 3628800.0);  // (t^2+2cos-2)/(2t^4)
    c = {sinc, cosc, cosc, sinc3, sinc3, cosc4};
    return c;
  }
  // Half-angle forms avoid the cancellation in 1 - cos and in t^2 + 2 cos - 2.
  const double s = std::sin(theta);
  const double sh = std::sin(0.5 * theta);
  const double t3 = t2 * theta;
  c.a0 = s / theta;
  c.b0 = 2.0 * sh * sh / t2;
  c.a1 = c.b0;
  c.b1 = (theta - s) / t3;
  c.a2 = c.b1;
  c.b2 = (theta - 2.0 * sh) * (theta + 2.0 * sh) / (2.0 * t2 * t2);
  return c;
}

Eigen::Matrix3d gamma0(const Eigen::Vector3d& phi) {
  const auto c = gamma_coefficients(phi.norm());
  return combine(1.0, c.a0, c.b0, phi);
}

Eigen::Matrix3d gamma1(const Eigen::Vector3d& phi) {
  const auto c = gamma_coefficients(phi.norm());
  return combine(1.0, c.a1, c.b1, phi);
}

Eigen::Matrix3d gamma2(const Eigen::Vector3d& phi) {
  const auto c = gamma_coefficients(phi.norm());
  return combine(0.5, c.a2, c.b2, phi);
}

Eigen::Matrix3d gamma1_inverse(const Eigen::Vector3d& phi) {
  const double theta = phi.norm();
  double c2 = 0.0;
  if (theta < kSeriesBelow) {
    const double t2 = theta * theta;
    c2 = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  } else {
    c2 = 1.0 / (theta * theta) - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  }
  return combine(1.0, -0.5, c2, phi);
}

Eigen::Vector3d so3_log(const Eigen::Matrix3d& rotation) {
  // Through the quaternion: stable near 0 and near pi, unlike acos of the trace.
  Eigen::Quaterniond q(rotation);
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double vn = q.vec().norm();
  if (vn < 1e-12) return 2.0 * q.vec() / q.w();
  const double angle = 2.0 * std::atan2(vn, q.w());
  return q.vec() * (angle / vn);
}

double yaw_of(const Eigen::Matrix3d& rotation) {
  return std::atan2(rotation(1, 0), rotation(0, 0));
}

bool yaw_defined(const Eigen::Matrix3d& rotation) { return std::abs(rotation(2, 0)) < 0.999999; }

Eigen::RowVector3d yaw_jacobian_body(const Eigen::Matrix3d& rotation) {
  const double r20 = rotation(2, 0);
  return Eigen::RowVector3d(0.0, rotation(2, 1), rotation(2, 2)) / (1.0 - r20 * r20);
}

Eigen::RowVector3d yaw_jacobian_world(const Eigen::Matrix3d& rotation) {
  const double r20 = rotation(2, 0);
  return (Eigen::Vector3d::UnitZ() - r20 * rotation.col(0)).transpose() / (1.0 - r20 * r20);
}

Eigen::Matrix3d rotation_from_rpy(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

double wrap_angle(double angle) {
  angle = std::remainder(angle, 2.0 * std::numbers::pi);
  return angle <= -std::numbers::pi ? angle + 2.0 * std::numbers::pi : angle;
}

}  // namespace semap::estimation
