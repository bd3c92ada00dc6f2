#pragma once

#include <Eigen/Geometry>

#include "semap/perception/depth_projection.hpp"
#include "semap/perception/synthetic_scene.hpp"

namespace semap::perception {

// Renders what a depth camera with a perfect segmenter sees of a SyntheticScene: z-depth
// and class per pixel, no return beyond max_range.
class SyntheticDepthCamera {
 public:
  SyntheticDepthCamera(const PinholeIntrinsics& intrinsics, float max_range);

  LabeledDepthImage render(const SyntheticScene& scene, const Eigen::Isometry3f& world_from_optical,
                           common::Stamp stamp) const;

  const PinholeIntrinsics& intrinsics() const { return intrinsics_; }

 private:
  PinholeIntrinsics intrinsics_;
  float max_range_;
};

}  // namespace semap::perception
