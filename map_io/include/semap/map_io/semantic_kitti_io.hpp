#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "semap/common/messages.hpp"

namespace semap::map_io {

// A malformed SemanticKITTI file; the message names the file and, where it applies, the line.
class KittiError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Number of classes after the official learning map: 0 = unlabelled (used as free space by
// the map), 1..19 = car .. traffic-sign.
inline constexpr int kKittiClasses = 20;

// The official learning map (semantic-kitti.yaml) from raw label ids (lower 16 bits of a
// .label entry) to 0..19; unknown ids map to 0.
std::uint16_t kitti_learning_map(std::uint32_t raw_label);
// Class names of the 20 learning classes, index = class.
const std::array<const char*, kKittiClasses>& kitti_class_names();

// The dataset's file name of scan `index`: six digits and `extension` (".bin", ".label").
std::string kitti_frame_name(std::size_t index, std::string_view extension);

// velodyne/NNNNNN.bin: perception::datasets::read_velodyne_bin (KITTI odometry's reader).
// labels/NNNNNN.label: uint32 per point, semantic id in the lower 16 bits (returned raw).
std::vector<std::uint32_t> read_kitti_labels(const std::filesystem::path& path);
// poses.txt: 12 numbers (row-major 3x4) per line, the left camera pose of each scan.
std::vector<Eigen::Isometry3d> read_kitti_poses(const std::filesystem::path& path);
// calib.txt: "Tr:" 12 numbers, velodyne to left camera.
Eigen::Isometry3d read_kitti_velodyne_to_camera(const std::filesystem::path& path);

// Writers of the same formats (synthetic sequences for tests and benchmarks); each throws
// KittiError naming the file when it cannot be written.
void write_kitti_scan(const std::filesystem::path& path, std::span<const Eigen::Vector4f> points);
void write_kitti_labels(const std::filesystem::path& path, std::span<const std::uint32_t> labels);
void write_kitti_poses(const std::filesystem::path& path, std::span<const Eigen::Isometry3d> poses);
// calib.txt with an identity P0 and `velo_to_cam` as Tr.
void write_kitti_calibration(const std::filesystem::path& path,
                             const Eigen::Isometry3d& velo_to_cam);

// One sequence folder (velodyne/, labels/, poses.txt, calib.txt).
class KittiSequence {
 public:
  explicit KittiSequence(std::filesystem::path folder);

  std::size_t size() const { return poses_.size(); }
  // Scan `index` in the world frame of the first camera pose, labels through the learning
  // map, origin = the LiDAR position. Throws KittiError if files are missing or disagree
  // (for the scan itself, read_velodyne_bin's message).
  common::LabeledCloud scan(std::size_t index) const;
  // LiDAR pose in the world: T_world_cam * T_cam_velo.
  Eigen::Isometry3d lidar_pose(std::size_t index) const;

 private:
  std::filesystem::path folder_;
  std::vector<Eigen::Isometry3d> poses_;
  Eigen::Isometry3d velo_to_cam_;
};

}  // namespace semap::map_io
