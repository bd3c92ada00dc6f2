#pragma once

#include <Eigen/Core>

namespace semap::estimation {

// Continuous-time IMU noise model shared by the InEKF and the ESKF baseline. Defaults are a
// consumer MEMS IMU (BMI088 class).
struct ImuNoise {
  double gyro_noise = 1.7e-4;        // rad/s/sqrt(Hz)  (0.01 deg/s/sqrt(Hz))
  double accel_noise = 2.0e-3;       // m/s^2/sqrt(Hz)  (200 ug/sqrt(Hz))
  double gyro_bias_walk = 2.0e-5;    // rad/s^2/sqrt(Hz)
  double accel_bias_walk = 3.0e-4;   // m/s^3/sqrt(Hz)
  double position_process = 1.0e-4;  // m/s/sqrt(Hz): keeps the position block well conditioned
};

struct FilterParams {
  ImuNoise noise;
  Eigen::Vector3d gravity = Eigen::Vector3d(0.0, 0.0, -9.80665);  // ENU
};

}  // namespace semap::estimation
