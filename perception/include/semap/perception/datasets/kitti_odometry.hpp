#pragma once

// KITTI odometry sequences (and SemanticKITTI's, which add labels): velodyne/NNNNNN.bin scans,
// times.txt, calib.txt, image_2/NNNNNN.png when downloaded, and the ground-truth poses of
// camera 0 (dataset/poses/SS.txt, or poses.txt in the sequence folder).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <opencv2/core/types.hpp>
#include <vector>

#include "semap/perception/datasets/dataset.hpp"
#include "semap/perception/datasets/lidar_frame.hpp"
#include "semap/perception/kitti_calib_text.hpp"
#include "semap/perception/lidar_projection.hpp"

namespace semap::perception::datasets {

// calib.txt of the odometry layout (P0..P3, Tr) or of the object layout (P0..P3, R0_rect,
// Tr_velo_to_cam).
struct KittiOdometryCalib {
  Eigen::Matrix<double, 3, 4> p2 = Eigen::Matrix<double, 3, 4>::Zero();  // P2, left colour camera
  Eigen::Matrix3d r0_rect = Eigen::Matrix3d::Identity();  // R0_rect; identity when absent
  Eigen::Isometry3d cam0_from_velo = Eigen::Isometry3d::Identity();  // Tr or Tr_velo_to_cam

  // Throws CalibrationError naming the file and key when P2 or the transform is missing or not
  // 12 numbers, or the transform or R0_rect is not rigid.
  static KittiOdometryCalib from_text(const KittiCalibText& text);

  // The rectified camera-0 frame, which the poses are given in, from the Velodyne: R0_rect Tr.
  Eigen::Isometry3d rect_from_velo() const;
  // A scan projected into image_2 of `image_size` (calib.txt does not give it): for
  // label_lidar_points.
  KittiCameraCalibration camera2(cv::Size image_size) const;
};

struct KittiOdometryOptions {
  // Empty: <sequence>/calib.txt. The calibration is a separate download from the scans; a
  // sequence without it can be read with a calib.txt written elsewhere (Tr of sequences 00-02
  // is in the KITTI devkit and in ../shared/data/real/README.md).
  std::filesystem::path calib;
};

struct KittiOdometrySequence {
  std::vector<LidarFrame> frames;  // in scan order
  KittiOdometryCalib calib;
  std::vector<InputProblem> problems;
};

// Scan NNNNNN takes row NNNNNN of times.txt and of the poses and image_2/NNNNNN.png when that
// exists. World = the Velodyne frame of the first pose row (scan 0, x forward, z up):
//   world_from_lidar_i = rect_from_velo^-1 P_0^-1 P_i rect_from_velo,   P_i = pose row i,
// P_0 being the identity in the dataset's own files. `poses_file` empty: <sequence>/poses.txt,
// else <sequence>/../../poses/<sequence name>.txt (the dataset's own layout). Rows beyond the
// scans present are not used. Problems, each skipping a scan: a file name that is not a scan
// number, a scan without a stamp or pose row, a row that does not parse. Throws DatasetError
// naming velodyne/, times.txt, the poses or calibration file when missing or unusable, and the
// poses' line 1 when the first pose, which defines the map frame, does not parse.
KittiOdometrySequence read_kitti_odometry(const std::filesystem::path& sequence_dir,
                                          const std::filesystem::path& poses_file = {},
                                          const KittiOdometryOptions& options = {});

}  // namespace semap::perception::datasets
