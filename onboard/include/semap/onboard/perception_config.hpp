#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <filesystem>

#include "semap/drivers/camera_driver.hpp"
#include "semap/perception/depth_projection.hpp"
#include "semap/perception/label_carrying.hpp"
#include "semap/perception/labelled_points.hpp"
#include "semap/perception/lidar_projection.hpp"
#include "semap/perception/stereo_depth.hpp"

namespace semap::onboard {

// camera: the colour camera (a V4L2 device on hardware, rendered on the simulated rig).
struct CameraConfig {
  drivers::CameraConfig driver;  // device, format, width, height, fps, buffers
  perception::PinholeIntrinsics intrinsics;
  Eigen::Vector3f mount_xyz{0.3f, 0.0f, 1.5f};  // camera centre in the body frame, m
  // Roll, pitch (positive tips the optical axis down), yaw of the camera in the body frame.
  Eigen::Vector3f mount_rpy_deg{0.0f, 15.0f, 0.0f};
  std::size_t ring = 4;

  // The camera's optical frame in the body frame (shared by the rig and perception).
  Eigen::Isometry3f body_from_optical() const;
};

enum class DepthSource {
  kAligned,  // a Z16 depth image aligned with the colour image, from a second device
  kStereo,   // the camera delivers a rectifiable stereo pair side by side in one frame
  // LiDAR scans (SensorRings::scans), labelled by projecting them into the segmented colour
  // image nearest in time; a segmenter without labels (geometry) maps whole scans, no image
  // needed. Set by semap-dataset kitti-odometry: the robot has no LiDAR driver yet, so the
  // YAML does not offer it.
  kLidar,
};

// depth.lidar: where the LiDAR sits and how its points project into the colour image.
struct LidarConfig {
  perception::KittiCameraCalibration camera;  // P_rect, R_rect, cam_from_lidar, image size
  Eigen::Isometry3f body_from_lidar = Eigen::Isometry3f::Identity();
};

// depth: where the labelled pixels get their range.
struct DepthConfig {
  DepthSource source = DepthSource::kAligned;
  // The depth device (aligned); on the simulated rig only the size and rate matter.
  drivers::CameraConfig driver;
  float depth_scale = 0.001f;  // metres per Z16 unit
  // Colour and depth frames (or scans) further apart do not pair.
  double sync_tolerance_s = 0.02;
  std::filesystem::path stereo_calibration;  // OpenCV YAML or KITTI calib_cam_to_cam.txt
  perception::StereoOptions stereo;
  LidarConfig lidar;
  perception::PointOptions points;  // stride, max_range, min_confidence, soft_labels
  std::size_t ring = 4;
};

// KITTI's calib_cam_to_cam.txt (.txt) or an OpenCV FileStorage file (anything else).
perception::StereoCalibration load_stereo_calibration(const std::filesystem::path& file);

// segmenter: what labels the pixels.
struct SegmenterConfig {
  // kDnn: a network OpenCV's DNN module reads (YAML `kind: dnn`, or `onnx`, its older name).
  // kGeometry: no labels, every depth pixel is map class 1 (geometry only).
  // kLabelImage: the colour frames are label images of map class ids (semap-dataset --labels).
  enum class Kind { kDnn, kPalette, kGeometry, kLabelImage } kind = Kind::kPalette;
  std::filesystem::path model_card;  // dnn
  // palette: YAML file; empty = the Cityscapes colours of the simulated world's classes
  std::filesystem::path palette;
  float confidence = 0.9f;  // palette: probability given to the colour's class
};

// perception: how often the network runs (docs/perception.md, "Networks slower than the
// camera").
struct SegmentRateConfig {
  // false: every frame mapped is segmented first, on the stage's thread (a network that keeps up
  // with the camera). true: the network runs on its own thread on the newest colour frame, as
  // often as it can (at most segment_hz), and each depth frame is labelled from the newest
  // segmentation, carried to it by the poses. Aligned depth only.
  bool carry_labels = false;
  double segment_hz = 0.0;       // 0: as often as the network can
  double max_label_age_s = 2.0;  // frames whose newest segmentation is older are not mapped
  perception::CarryOptions carry;
};

}  // namespace semap::onboard
