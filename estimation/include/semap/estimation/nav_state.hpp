#pragma once

#include <Eigen/Core>

namespace semap::estimation {

using Vector15 = Eigen::Matrix<double, 15, 1>;
using Matrix15 = Eigen::Matrix<double, 15, 15>;

// Navigation state in the local ENU frame: body (FLU) to world rotation, velocity and
// position of the body origin, and the IMU biases. Error vectors of every filter are ordered
// [rotation, velocity, position, gyro bias, accel bias], three components each.
struct NavState {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();
};

// Block offsets in the 15-dim error vector.
inline constexpr int kRot = 0;
inline constexpr int kVel = 3;
inline constexpr int kPos = 6;
inline constexpr int kGyroBias = 9;
inline constexpr int kAccelBias = 12;

}  // namespace semap::estimation
