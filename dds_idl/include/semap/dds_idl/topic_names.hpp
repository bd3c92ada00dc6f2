#pragma once

#include <string>
#include <string_view>

#include "semap/dds_idl/qos.hpp"

namespace semap::dds_idl {

// The topics semap publishes, named as ROS 2 maps `/<ns>/semap/<leaf>` onto DDS.
enum class SemapTopic {
  kOdometry,
  kPose,
  kGnss,
  kImu,
  kMapBlocks,
  kMapInfo,
  kMapCloud,
  kMapCloudUpdates,
  kHealth,
  kCostmap,
  kCostmapUpdates,
  kTf,       // rt/tf, or rt/<ns>/tf: ROS's transform tree, not under semap/
  kTfStatic  // rt/tf_static, or rt/<ns>/tf_static
};

// "rt/semap/odometry" for an empty namespace, "rt/robot1/semap/odometry" for "robot1".
// Throws std::invalid_argument for a namespace that is not a valid ROS 2 name.
std::string topic_name(std::string_view ns, SemapTopic topic);

// Reliability of the sensor streams (odometry, imu, gnss): best effort as ROS's sensor-data
// QoS, which a reliable subscriber (RViz's default) does not match; or reliable, which every
// subscriber matches, at the cost of retransmissions of samples only the newest of which matters.
enum class SensorReliability { kBestEffort, kReliable };
// "best_effort" | "reliable"; throws std::invalid_argument otherwise.
SensorReliability sensor_reliability_from_string(const std::string& name);

// The QoS of each topic, used by writers and readers alike (docs/dds.md lists them).
Qos topic_qos(SemapTopic topic, SensorReliability sensors = SensorReliability::kBestEffort);

}  // namespace semap::dds_idl
