#pragma once

#include <Eigen/Geometry>
#include <filesystem>
#include <optional>

namespace semap::perception::datasets {

// One LiDAR scan of a dataset (read_kitti_odometry), its camera image when there is one, and
// the LiDAR's pose.
struct LidarFrame {
  double stamp_s = 0.0;        // the dataset's clock (KITTI: seconds since the first scan)
  std::filesystem::path scan;  // read_velodyne_bin
  std::optional<std::filesystem::path> image;  // the image to label the scan with
  Eigen::Isometry3d world_from_lidar = Eigen::Isometry3d::Identity();
};

}  // namespace semap::perception::datasets
