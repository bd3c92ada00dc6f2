#pragma once

#include <Eigen/Geometry>
#include <stdexcept>
#include <string>
#include <vector>

namespace semap::apps {

// "tx,ty,tz,qw,qx,qy,qz" as given on the command line; the quaternion is normalised.
inline Eigen::Isometry3d transform_from_values(const std::vector<double>& v) {
  if (v.size() != 7) {
    throw std::invalid_argument("--transform needs 7 values tx,ty,tz,qw,qx,qy,qz, got " +
                                std::to_string(v.size()));
  }
  const Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
  if (!(q.norm() > 1e-9)) throw std::invalid_argument("--transform: zero quaternion");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return T;
}

}  // namespace semap::apps
