#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core/mat.hpp>

#include "semap/perception/depth_projection.hpp"
#include "semap/perception/kitti_calib_text.hpp"

namespace semap::perception {

// What depth from a side-by-side stereo camera (one frame: left half | right half, as UVC
// stereo cameras deliver it) needs: how to rectify each half and the rectified geometry.
struct StereoCalibration {
  cv::Size half_size;           // one half, as calibrated
  PinholeIntrinsics rectified;  // of the rectified left image; the right one shares it
  float baseline_m = 0.0f;      // between the camera centres, right camera to the right
  // Rotation from the rectified left frame to the left camera's optical frame (R1^T of
  // cv::stereoRectify; identity for images that come rectified). Depth is in the rectified
  // frame, so a cloud from it is placed with
  //   body_from_rectified = body_from_left_optical * left_from_rectified.
  Eigen::Matrix3f left_from_rectified = Eigen::Matrix3f::Identity();
  // cv::initUndistortRectifyMap maps (CV_16SC2 + CV_16UC1) for each half; empty when the
  // images come rectified.
  cv::Mat left_map1, left_map2, right_map1, right_map2;

  bool needs_remap() const { return !left_map1.empty(); }

  // An OpenCV FileStorage file (YAML or XML) with the keys OpenCV's stereo_calib sample
  // writes: M1 D1 M2 D2 (intrinsics.yml: 3x3 camera matrices, 4/5/8/12/14 distortion
  // coefficients) and R T (extrinsics.yml: 3x3 rotation, 3-vector translation taking left-camera
  // points into the right camera, in metres), in one file, plus image_width and image_height of
  // one half (the sample does not write them). Rectifies with cv::stereoRectify, alpha 0 (only
  // valid pixels remain, so no black borders reach the matcher or the segmenter). Throws
  // CalibrationError naming the file and the key: missing, wrong shape, or a rig that is not
  // side by side.
  static StereoCalibration from_opencv_yaml(const std::filesystem::path& path);

  // KITTI calib_cam_to_cam.txt: the images are already rectified, no remap. P_rect_0<left>
  // gives fx, fy, cx, cy, S_rect_0<left> the size and the baseline is
  //   B = (P_left[0,3] - P_right[0,3]) / fx.
  // Defaults: the colour pair 2 (left) and 3 (right).
  static StereoCalibration from_kitti(const KittiCalibText& cam_to_cam, int left_camera = 2,
                                      int right_camera = 3);
  static StereoCalibration load_kitti(const std::filesystem::path& cam_to_cam, int left_camera = 2,
                                      int right_camera = 3);
};

}  // namespace semap::perception
