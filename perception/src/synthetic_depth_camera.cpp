#include "semap/perception/synthetic_depth_camera.hpp"

namespace semap::perception {

SyntheticDepthCamera::SyntheticDepthCamera(const PinholeIntrinsics& intrinsics, float max_range)
    : intrinsics_(intrinsics), max_range_(max_range) {}

LabeledDepthImage SyntheticDepthCamera::render(const SyntheticScene& scene,
                                               const Eigen::Isometry3f& world_from_optical,
                                               common::Stamp stamp) const {
  const std::size_t n = static_cast<std::size_t>(intrinsics_.width) * intrinsics_.height;
  LabeledDepthImage image;
  image.stamp = stamp;
  image.depth.assign(n, 0.0f);
  image.labels.assign(n, 0);
  const Eigen::Matrix3f rotation = world_from_optical.linear();
  const Eigen::Vector3f origin = world_from_optical.translation();
  for (int v = 0; v < intrinsics_.height; ++v) {
    for (int u = 0; u < intrinsics_.width; ++u) {
      const Eigen::Vector3f ray = intrinsics_.ray(static_cast<float>(u), static_cast<float>(v));
      const float length = ray.norm();
      // A range limit on the ray becomes a depth limit of range * z / |ray| (z = 1).
      const auto hit = scene.cast(origin, rotation * (ray / length), max_range_);
      if (!hit) continue;
      const std::size_t i = static_cast<std::size_t>(v) * intrinsics_.width + u;
      image.depth[i] = hit->range / length;
      image.labels[i] = hit->label;
    }
  }
  return image;
}

}  // namespace semap::perception
