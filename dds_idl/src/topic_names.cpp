#include "semap/dds_idl/topic_names.hpp"

#include <cctype>
#include <stdexcept>

namespace semap::dds_idl {

namespace {

std::string_view leaf(SemapTopic topic) {
  switch (topic) {
    case SemapTopic::kOdometry:
      return "odometry";
    case SemapTopic::kPose:
      return "pose";
    case SemapTopic::kGnss:
      return "gnss";
    case SemapTopic::kImu:
      return "imu";
    case SemapTopic::kMapBlocks:
      return "map_blocks";
    case SemapTopic::kMapInfo:
      return "map_info";
    case SemapTopic::kMapCloud:
      return "map_cloud";
    case SemapTopic::kMapCloudUpdates:
      return "map_cloud_updates";
    case SemapTopic::kHealth:
      return "health";
    case SemapTopic::kCostmap:
      return "costmap";
    case SemapTopic::kCostmapUpdates:
      return "costmap_updates";
    case SemapTopic::kTf:
      return "tf";
    case SemapTopic::kTfStatic:
      return "tf_static";
  }
  throw std::invalid_argument("unknown SemapTopic");
}

// ROS 2 names: tokens of letters, digits and _ separated by single /, no token starting with a
// digit, no trailing /.
void validate_namespace(std::string_view ns) {
  bool token_start = true;
  for (char c : ns) {
    const bool ok = std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/';
    if (!ok || (c == '/' && token_start)) {
      throw std::invalid_argument("DDS namespace '" + std::string(ns) +
                                  "' is not a ROS 2 name (letters, digits, _ and single /)");
    }
    if (token_start && std::isdigit(static_cast<unsigned char>(c))) {
      throw std::invalid_argument("DDS namespace '" + std::string(ns) +
                                  "': a name token must not start with a digit");
    }
    token_start = c == '/';
  }
  if (!ns.empty() && ns.back() == '/') {
    throw std::invalid_argument("DDS namespace '" + std::string(ns) + "' must not end with /");
  }
}

}  // namespace

std::string topic_name(std::string_view ns, SemapTopic topic) {
  validate_namespace(ns);
  std::string name = "rt/";
  if (!ns.empty()) {
    name += ns;
    name += '/';
  }
  if (topic != SemapTopic::kTf && topic != SemapTopic::kTfStatic) name += "semap/";
  name += leaf(topic);
  return name;
}

SensorReliability sensor_reliability_from_string(const std::string& name) {
  if (name == "best_effort") return SensorReliability::kBestEffort;
  if (name == "reliable") return SensorReliability::kReliable;
  throw std::invalid_argument("unknown sensor reliability '" + name +
                              "' (best_effort or reliable)");
}

Qos topic_qos(SemapTopic topic, SensorReliability sensors) {
  switch (topic) {
    case SemapTopic::kOdometry:
    case SemapTopic::kGnss:
    case SemapTopic::kImu: {
      Qos qos;
      if (sensors == SensorReliability::kReliable) {
        qos.reliable();
      } else {
        qos.best_effort();
      }
      return std::move(qos.keep_last(topic == SemapTopic::kOdometry ? 1 : 10));
    }
    case SemapTopic::kPose:
      return std::move(Qos().reliable().keep_last(1));
    case SemapTopic::kMapBlocks:
    case SemapTopic::kMapInfo:
    case SemapTopic::kMapCloud:  // the whole map: a late joiner gets the current one
    case SemapTopic::kCostmap:   // as nav2's static layer subscribes to `map`
      // Late joiners get the current version of every block from the writer's history.
      return std::move(Qos().reliable().transient_local().keep_last(1));
    case SemapTopic::kHealth:
    case SemapTopic::kMapCloudUpdates:
    case SemapTopic::kCostmapUpdates:
      return std::move(Qos().reliable().keep_last(10));
    case SemapTopic::kTf:  // as tf2_ros' broadcaster
      return std::move(Qos().reliable().keep_last(100));
    case SemapTopic::kTfStatic:  // as tf2_ros' static broadcaster: late joiners get the tree
      return std::move(Qos().reliable().transient_local().keep_last(1));
  }
  throw std::invalid_argument("unknown SemapTopic");
}

}  // namespace semap::dds_idl
