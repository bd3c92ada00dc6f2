#pragma once

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "semap/perception/depth_projection.hpp"
#include "semap/perception/stereo_calibration.hpp"

namespace cv {
class StereoSGBM;
}

namespace semap::perception {

// cv::StereoSGBM settings; the defaults suit VGA-sized halves.
struct StereoOptions {
  int num_disparities = 128;  // search range in pixels, a positive multiple of 16; the left
                              // num_disparities columns get no depth
  int block_size = 5;         // odd matching window side
  int uniqueness = 10;        // percent by which the best match must beat the second
  int speckle_window = 100;   // largest disparity blob (pixels) discarded as noise; 0 = off
  int speckle_range = 2;      // disparity spread (pixels) within one blob
};

// One side-by-side frame turned into what the segmenter and cloud_from_depth need.
struct StereoFrame {
  cv::Mat left_bgr;              // rectified left image, CV_8UC3: what the segmenter sees
  cv::Mat depth;                 // CV_32FC1 z-depth in metres aligned with it, 0 = none
  PinholeIntrinsics intrinsics;  // of the rectified left image
  Eigen::Matrix3f left_from_rectified = Eigen::Matrix3f::Identity();  // see StereoCalibration
};

// Depth from a stereo pair delivered side by side in one frame (left half | right half).
class StereoDepth {
 public:
  // Throws std::invalid_argument naming an option outside its range.
  explicit StereoDepth(StereoCalibration calibration, const StereoOptions& options = {});
  // Copies would share the matcher's scratch buffers.
  StereoDepth(const StereoDepth&) = delete;
  StereoDepth& operator=(const StereoDepth&) = delete;
  StereoDepth(StereoDepth&&) = default;
  StereoDepth& operator=(StereoDepth&&) = default;

  // `frame`: CV_8UC3 (BGR) or CV_8UC1 (grey), twice the calibrated width and the calibrated
  // height; anything else throws std::invalid_argument naming both sizes.
  StereoFrame compute(const cv::Mat& frame);

  const StereoCalibration& calibration() const { return calibration_; }

 private:
  StereoCalibration calibration_;
  cv::Ptr<cv::StereoSGBM> sgbm_;
};

}  // namespace semap::perception
