#pragma once

// A SemanticKITTI sequence written by a test in the dataset's formats: velodyne/*.bin,
// labels/*.label (raw ids), poses.txt (camera poses) and calib.txt, in a temporary folder.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "semap/map_io/semantic_kitti_io.hpp"

namespace semap::map_io::testing {

class KittiTestSequence {
 public:
  KittiTestSequence() {
    const auto* test = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() /
           ("semap_kitti_" + std::string(test->test_suite_name()) + "_" + test->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_ / "velodyne");
    std::filesystem::create_directories(dir_ / "labels");
    std::filesystem::create_directories(dir_ / "predictions");
  }
  ~KittiTestSequence() { std::filesystem::remove_all(dir_); }
  KittiTestSequence(const KittiTestSequence&) = delete;
  KittiTestSequence& operator=(const KittiTestSequence&) = delete;

  const std::filesystem::path& dir() const { return dir_; }

  // calib.txt with the dataset's velodyne-to-camera axis swap as Tr, and poses.txt with the
  // camera poses that put the LiDAR at each of `lidar_positions`, axes as the world's.
  void write_poses(const std::vector<Eigen::Vector3d>& lidar_positions) {
    Eigen::Isometry3d velo_to_cam = Eigen::Isometry3d::Identity();
    velo_to_cam.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    write_kitti_calibration(dir_ / "calib.txt", velo_to_cam);
    std::vector<Eigen::Isometry3d> poses;
    for (const Eigen::Vector3d& position : lidar_positions) {
      poses.push_back(Eigen::Translation3d(position) * velo_to_cam.inverse());
    }
    write_kitti_poses(dir_ / "poses.txt", poses);
  }

  // Scan `index` (points in the sensor frame) and its ground truth (raw label ids).
  void write_scan(std::size_t index, const std::vector<Eigen::Vector3f>& points,
                  const std::vector<std::uint32_t>& raw_labels) {
    std::vector<Eigen::Vector4f> xyzr;
    for (const Eigen::Vector3f& p : points) xyzr.emplace_back(p.x(), p.y(), p.z(), 0.0f);
    write_kitti_scan(dir_ / "velodyne" / kitti_frame_name(index, ".bin"), xyzr);
    write_labels("labels", index, raw_labels);
  }
  // Raw label ids of scan `index` in `folder` (labels or predictions).
  void write_labels(const std::string& folder, std::size_t index,
                    const std::vector<std::uint32_t>& raw_labels) {
    write_kitti_labels(dir_ / folder / kitti_frame_name(index, ".label"), raw_labels);
  }
  void write_bytes(const std::string& relative, const void* data, std::size_t bytes) {
    std::ofstream(dir_ / relative, std::ios::binary)
        .write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  }

 private:
  std::filesystem::path dir_;
};

// Raw ids of the SemanticKITTI classes the tests use.
inline constexpr std::uint32_t kRawUnlabeled = 0, kRawCar = 10, kRawRoad = 40, kRawSidewalk = 48,
                               kRawBuilding = 50;

// The isolated-points scene: points 1 m apart along x from 2 m (no two share a cell or a
// kernel support), truth and predictions given per point.
inline std::vector<Eigen::Vector3f> isolated_points(std::size_t count) {
  std::vector<Eigen::Vector3f> points;
  for (std::size_t i = 0; i < count; ++i) {
    points.emplace_back(2.05f + static_cast<float>(i), 0.05f, 0.05f);
  }
  return points;
}

}  // namespace semap::map_io::testing
