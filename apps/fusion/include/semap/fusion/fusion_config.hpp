#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "semap/common/config.hpp"
#include "semap/dds_idl/map_description.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/mapping/map_params.hpp"

namespace semap::fusion {

// One robot the fusion follows.
struct RobotSource {
  std::string ns;  // its topic namespace
  // Pose of the robot's map frame in the fused frame: a point p of the robot's map lies at
  // T_fused_robot * p in the fused map.
  Eigen::Isometry3d T_fused_robot = Eigen::Isometry3d::Identity();
};

struct MapFusionConfig {
  std::vector<RobotSource> robots;
  dds_idl::MapPublisherConfig output;  // namespace and rates of the fused map
  // Shape every robot's map has, and the fused map's (same cells, same classes).
  dds_idl::MapDescription description;
  mapping::MapMethod method = mapping::MapMethod::kBki;
  double prior = 0.001;  // the robots' Dirichlet prior alpha_0
};

// x, y, z (m), roll, pitch, yaw (rad; R = Rz(yaw) Ry(pitch) Rx(roll), as ROS' fixed-axis
// RPY). Throws std::invalid_argument unless there are six finite values.
Eigen::Isometry3d transform_from_xyz_rpy(const std::vector<double>& v);

// Reads the `fusion:` section strictly (unknown keys, ranges, duplicate or unknown robots
// throw common::ConfigError naming file, line and key):
//   fusion:
//     robots: [robot1, robot2]
//     transforms: { robot2: [10, 0, 0, 0, 0, 0] }   # per robot x y z roll pitch yaw; default 0
//     output: fused
//     frame_id: map
//     publish_hz: 2
//     cloud_hz: 0.5
//     method: bki          # bki | csm
//     prior: 0.001
//     resolution: 0.1
//     block_cells: 8
//     num_classes: 4
//     class_names: [free, ground, wall, vegetation]
MapFusionConfig read_fusion_config(const common::ConfigSection& fusion);

}  // namespace semap::fusion
