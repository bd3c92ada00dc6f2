#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>

#include "semap/common/messages.hpp"
#include "semap/common/stamp.hpp"
#include "semap/dds_idl/types.hpp"

namespace semap::dds_idl {

// The clock of the stamps in DDS headers. Inside, the pipeline's stamps are CLOCK_MONOTONIC;
// at the DDS boundary they become kRealtime, ROS time (the system clock, which TF, RViz, nav2
// and message_filters compare against), through common::ClockOffset, or stay kMonotonic.
enum class StampClock { kRealtime, kMonotonic };

// Process-wide, set once at start (dds.stamp_clock); kRealtime unless set.
void set_stamp_clock(StampClock clock);
StampClock stamp_clock();
// "realtime" | "monotonic"; throws std::invalid_argument otherwise.
StampClock stamp_clock_from_string(const std::string& name);

// A pipeline stamp as a header stamp in the stamp clock, split into sec/nanosec, and back.
// Negative times are clamped to zero (builtin_interfaces/Time cannot carry them meaningfully).
msg::Time to_msg_time(common::Stamp stamp);
common::Stamp from_msg_time(const msg::Time& t);
// A header of `stamp` (to_msg_time) in `frame_id`, which it borrows: valid during the write.
void set_header(common::Stamp stamp, const std::string& frame_id, msg::Header& h);

// A pose estimate with its velocity, the plain form of nav_msgs/Odometry. Covariances are in
// ROS order: (x, y, z, rotation about x, y, z); twist in the body (child) frame.
struct PoseEstimate {
  common::Stamp stamp;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // body to map
  Eigen::Vector3d velocity_body = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_body = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 6, 6> pose_covariance = Eigen::Matrix<double, 6, 6>::Identity();
  Eigen::Matrix<double, 6, 6> twist_covariance = Eigen::Matrix<double, 6, 6>::Identity();
};

// The `frame_id` strings are borrowed: they must outlive the filled message.
void to_msg(const common::ImuSample& s, const std::string& frame_id, double gyro_variance,
            double accel_variance, msg::Imu& out);
void to_msg(const common::GnssFix& f, const std::string& frame_id, msg::NavSatFix& out);
// The transform from `child_frame_id` to `frame_id` (a point in the child frame, expressed in the
// parent frame), as TF carries it. The frame names are borrowed: valid during the write.
void to_msg(const Eigen::Isometry3d& parent_from_child, common::Stamp stamp,
            const std::string& frame_id, const std::string& child_frame_id,
            msg::TransformStamped& out);
void to_msg(const PoseEstimate& p, const std::string& frame_id, const std::string& child_frame_id,
            msg::Odometry& out);
void to_msg(const PoseEstimate& p, const std::string& frame_id,
            msg::PoseWithCovarianceStamped& out);

common::ImuSample from_msg(const msg::Imu& m);
common::GnssFix from_msg(const msg::NavSatFix& m);
PoseEstimate from_msg(const msg::Odometry& m);
PoseEstimate from_msg(const msg::PoseWithCovarianceStamped& m);

}  // namespace semap::dds_idl
