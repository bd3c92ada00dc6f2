#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "semap/common/messages.hpp"

namespace semap::mapping {

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

// Back-projects every `stride`-th pixel with a return in (0, max_range] into the target frame
// through `target_from_optical`; the cloud's origin is the camera centre in that frame.
// Non-finite or out-of-range depths are skipped.
common::LabeledCloud back_project(const LabeledDepthImage& image,
                                  const PinholeIntrinsics& intrinsics,
                                  const Eigen::Isometry3f& target_from_optical, int stride,
                                  float max_range);

}  // namespace semap::mapping
