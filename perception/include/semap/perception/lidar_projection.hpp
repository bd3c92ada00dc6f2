#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>
#include <opencv2/core/types.hpp>
#include <span>

#include "semap/common/messages.hpp"
#include "semap/perception/kitti_calib_text.hpp"
#include "semap/perception/labelled_points.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// How a KITTI Velodyne scan projects into one rectified camera image, from the raw dataset's
// calib_cam_to_cam.txt (S_rect_0i, P_rect_0i, R_rect_00) and calib_velo_to_cam.txt (R, T).
struct KittiCameraCalibration {
  cv::Size image_size;                                                       // S_rect_0i
  Eigen::Matrix<double, 3, 4> p_rect = Eigen::Matrix<double, 3, 4>::Zero();  // P_rect_0i
  Eigen::Matrix3d r_rect = Eigen::Matrix3d::Identity();                      // R_rect_00
  Eigen::Isometry3d cam_from_lidar = Eigen::Isometry3d::Identity();          // Tr_velo_to_cam

  // P_rect R_rect Tr_velo_to_cam as one 3x4 matrix: see label_lidar_points, equation (1).
  Eigen::Matrix<float, 3, 4> image_from_lidar() const;

  // `camera` picks P_rect_0<camera> and S_rect_0<camera> (2 = left colour camera, 0..3).
  // Throws CalibrationError naming the file and key (missing, wrong count, not a number) and
  // std::invalid_argument for a camera outside 0..3.
  static KittiCameraCalibration from_text(const KittiCalibText& cam_to_cam,
                                          const KittiCalibText& velo_to_cam, int camera = 2);
  static KittiCameraCalibration load(const std::filesystem::path& cam_to_cam,
                                     const std::filesystem::path& velo_to_cam, int camera = 2);
};

// Labels LiDAR points (lidar frame) with the class of the pixel they project to and returns them
// in the body frame, origin = the lidar centre in the body frame; labels are the segmentation's
// probabilities when options.soft_labels and seg.soft(), hard labels otherwise; the caller sets
// the stamp. Every point is either in the cloud or counted in `drops`: no_depth (non-finite),
// out_of_range (beyond options.max_range from the lidar), out_of_image (behind the camera or
// outside the image), no_label, low_confidence. options.stride does not apply. A segmentation
// whose size is not the calibration's image size throws std::invalid_argument naming both.
common::LabeledCloud label_lidar_points(std::span<const Eigen::Vector3f> points_lidar,
                                        const Segmentation& seg,
                                        const KittiCameraCalibration& calib,
                                        const Eigen::Isometry3f& body_from_lidar,
                                        const PointOptions& options, DropCounts& drops);

// A scan without labels (geometry only): every finite point within options.max_range of the
// LiDAR becomes map class 1 ("something is there") of a `num_classes` map, in the body frame,
// origin = the LiDAR centre; the others are counted as no_depth or out_of_range.
common::LabeledCloud occupied_lidar_points(std::span<const Eigen::Vector3f> points_lidar,
                                           int num_classes,
                                           const Eigen::Isometry3f& body_from_lidar,
                                           const PointOptions& options, DropCounts& drops);

}  // namespace semap::perception
