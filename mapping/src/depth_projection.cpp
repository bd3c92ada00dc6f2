#include "semap/mapping/depth_projection.hpp"

#include <cmath>

namespace semap::mapping {

PinholeIntrinsics PinholeIntrinsics::from_fov(int width, int height, float horizontal_fov_rad) {
  PinholeIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = static_cast<float>(width) / (2.0f * std::tan(horizontal_fov_rad / 2.0f));
  k.fy = k.fx;
  k.cx = (static_cast<float>(width) - 1.0f) / 2.0f;
  k.cy = (static_cast<float>(height) - 1.0f) / 2.0f;
  return k;
}

Eigen::Matrix3f optical_to_flu() {
  Eigen::Matrix3f r;
  // Columns: optical x (right) = -body y, optical y (down) = -body z, optical z = body x.
  r << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  return r;
}

common::LabeledCloud back_project(const LabeledDepthImage& image,
                                  const PinholeIntrinsics& intrinsics,
                                  const Eigen::Isometry3f& target_from_optical, int stride,
                                  float max_range) {
  common::LabeledCloud cloud;
  cloud.stamp = image.stamp;
  cloud.origin = target_from_optical.translation();
  const int step = stride < 1 ? 1 : stride;
  const std::size_t expected =
      static_cast<std::size_t>(intrinsics.width) * static_cast<std::size_t>(intrinsics.height);
  if (image.depth.size() != expected || image.labels.size() != expected) return cloud;
  for (int v = 0; v < intrinsics.height; v += step) {
    for (int u = 0; u < intrinsics.width; u += step) {
      const std::size_t i = static_cast<std::size_t>(v) * intrinsics.width + u;
      const float z = image.depth[i];
      if (!std::isfinite(z) || z <= 0.0f) continue;
      const Eigen::Vector3f p_optical =
          intrinsics.ray(static_cast<float>(u), static_cast<float>(v)) * z;
      if (p_optical.norm() > max_range) continue;
      cloud.points.push_back(target_from_optical * p_optical);
      cloud.labels.push_back(image.labels[i]);
    }
  }
  return cloud;
}

}  // namespace semap::mapping
