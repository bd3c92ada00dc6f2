#include "semap/estimation/invariant_nav_space.hpp"

#include "semap/estimation/so3.hpp"

namespace semap::estimation {

NavState InvariantNavSpace::plus(const NavState& x, const Vector15& d) {
  const Eigen::Vector3d phi = d.segment<3>(kRot);
  const Eigen::Matrix3d j = gamma1(phi);
  NavState out;
  out.rotation = x.rotation * gamma0(phi);
  out.velocity = x.velocity + x.rotation * (j * d.segment<3>(kVel));
  out.position = x.position + x.rotation * (j * d.segment<3>(kPos));
  out.gyro_bias = x.gyro_bias + d.segment<3>(kGyroBias);
  out.accel_bias = x.accel_bias + d.segment<3>(kAccelBias);
  return out;
}

Vector15 InvariantNavSpace::minus(const NavState& y, const NavState& x) {
  Vector15 d;
  const Eigen::Vector3d phi = so3_log(x.rotation.transpose() * y.rotation);
  const Eigen::Matrix3d j_inv = gamma1_inverse(phi);
  d.segment<3>(kRot) = phi;
  d.segment<3>(kVel) = j_inv * (x.rotation.transpose() * (y.velocity - x.velocity));
  d.segment<3>(kPos) = j_inv * (x.rotation.transpose() * (y.position - x.position));
  d.segment<3>(kGyroBias) = y.gyro_bias - x.gyro_bias;
  d.segment<3>(kAccelBias) = y.accel_bias - x.accel_bias;
  return d;
}

}  // namespace semap::estimation
