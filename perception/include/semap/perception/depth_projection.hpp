#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "semap/common/messages.hpp"

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

// A depth image (z-depth in metres, 0 = no return) with a per-pixel class from a segmenter,
// both row-major, width * height.
struct LabeledDepthImage {
  common::Stamp stamp;
  std::vector<float> depth;
  std::vector<std::uint16_t> labels;
};

// Rotation from the optical frame to a FLU body frame (optical z forward = body x).
Eigen::Matrix3f optical_to_flu();

}  // namespace semap::perception
