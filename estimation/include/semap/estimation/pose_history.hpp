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
  // The filter's position uncertainty at this pose, 1 sigma along its least certain axis (m,
  // position_sigma_m below); 0 when nobody estimated it (poses a dataset gives).
  double position_sigma_m = 0.0;

  // World from body, for transforming what the robot sensed at this pose.
  Eigen::Isometry3f world_from_body() const {
    Eigen::Isometry3f t = Eigen::Isometry3f::Identity();
    t.linear() = orientation.toRotationMatrix().cast<float>();
    t.translation() = position.cast<float>();
    return t;
  }
};

// 1 sigma along the least certain axis of a position covariance (m^2): the square root of its
// largest eigenvalue.
double position_sigma_m(const Eigen::Matrix3d& covariance);

// The last `capacity` filter poses in a ring, for interpolating the pose at a sensor stamp
// (slerp for the orientation, linear for position and velocity; the larger position sigma of
// the two poses around the stamp).
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
