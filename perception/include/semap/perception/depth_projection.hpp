#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace semap::perception {

// Pinhole model in the optical frame (x right, y down, z forward).
struct PinholeIntrinsics {
  int width = 0;
  int height = 0;
  float fx = 0.0f;
  float fy = 0.0f;
  float cx = 0.0f;
  float cy = 0.0f;

  static PinholeIntrinsics from_fov(int width, int height, float horizontal_fov_rad);
  // Unit-free ray through pixel (u, v) with z = 1.
  Eigen::Vector3f ray(float u, float v) const {
    return Eigen::Vector3f((u - cx) / fx, (v - cy) / fy, 1.0f);
  }
};

// Rotation from the optical frame to a FLU body frame (optical z forward = body x).
Eigen::Matrix3f optical_to_flu();

}  // namespace semap::perception
