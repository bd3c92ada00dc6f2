#pragma once

#include <Eigen/Core>

#include "semap/estimation/nav_state.hpp"

namespace semap::estimation {

// Continuous-time IMU noise model shared by the InEKF and the ESKF baseline, per body axis
// (x, y, z), as IMU datasheets give it. Defaults are a consumer MEMS IMU (BMI088 class), the
// same on every axis.
struct ImuNoise {
  Eigen::Vector3d gyro_noise = Eigen::Vector3d::Constant(1.7e-4);       // rad/s/sqrt(Hz)
  Eigen::Vector3d accel_noise = Eigen::Vector3d::Constant(2.0e-3);      // m/s^2/sqrt(Hz) (200 ug)
  Eigen::Vector3d gyro_bias_walk = Eigen::Vector3d::Constant(2.0e-5);   // rad/s^2/sqrt(Hz)
  Eigen::Vector3d accel_bias_walk = Eigen::Vector3d::Constant(3.0e-4);  // m/s^3/sqrt(Hz)
  double position_process = 1.0e-4;  // m/s/sqrt(Hz): keeps the position block well conditioned
};

struct FilterParams {
  ImuNoise noise;
  Eigen::Vector3d gravity = Eigen::Vector3d(0.0, 0.0, -9.80665);  // ENU
};

// Diagonal of the continuous process noise Q = diag(Qg, Qa, qp I, Qbg, Qba) shared by both
// filters, in their error order. The IMU blocks are body-frame, which is where both filters'
// rotation errors live; a filter whose velocity error is world-frame rotates Qa itself.
inline Vector15 process_noise_diagonal(const ImuNoise& noise) {
  Vector15 q;
  q.segment<3>(kRot) = noise.gyro_noise.cwiseAbs2();
  q.segment<3>(kVel) = noise.accel_noise.cwiseAbs2();
  q.segment<3>(kPos).setConstant(noise.position_process * noise.position_process);
  q.segment<3>(kGyroBias) = noise.gyro_bias_walk.cwiseAbs2();
  q.segment<3>(kAccelBias) = noise.accel_bias_walk.cwiseAbs2();
  return q;
}

}  // namespace semap::estimation
