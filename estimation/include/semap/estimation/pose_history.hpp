#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <vector>

#include "semap/common/stamp.hpp"

namespace semap::estimation {

struct StampedPose {
  common::Stamp stamp;
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // body to world
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();

  // World from body, for transforming what the robot sensed at this pose.
  Eigen::Isometry3f world_from_body() const {
    Eigen::Isometry3f t = Eigen::Isometry3f::Identity();
    t.linear() = orientation.toRotationMatrix().cast<float>();
    t.translation() = position.cast<float>();
    return t;
  }
};

// The last `capacity` filter poses in a ring, for interpolating the pose at a sensor stamp
// (slerp for the orientation, linear for position and velocity).
class PoseHistory {
 public:
  explicit PoseHistory(std::size_t capacity);

  // Stamps must increase; an older or equal stamp is ignored.
  void push(const StampedPose& pose);
  // Empty outside [oldest, newest].
  std::optional<StampedPose> at(common::Stamp stamp) const;

  std::size_t size() const { return size_; }
  std::optional<StampedPose> newest() const;
  void clear() { size_ = 0; }

 private:
  const StampedPose& get(std::size_t i) const;  // 0 = oldest

  std::vector<StampedPose> ring_;
  std::size_t head_ = 0;  // next write
  std::size_t size_ = 0;
};

}  // namespace semap::estimation
