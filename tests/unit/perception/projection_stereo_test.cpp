#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "semap/perception/stereo_depth.hpp"

namespace semap::perception {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr int kWidth = 640;
constexpr int kHeight = 480;
constexpr double kFocal = 500.0;
constexpr double kBaseline = 0.12;
constexpr double kPlaneZ = 3.0;
constexpr int kDisparity = 20;  // f B / Z = 500 * 0.12 / 3

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "semap_stereo_test";
  std::filesystem::create_directories(dir);
  return dir / name;
}

// A fronto-parallel plane at kPlaneZ covered in random texture: the right camera, kBaseline to
// the right, sees every texel kDisparity pixels further left, right(u) = left(u + d).
cv::Mat side_by_side_plane() {
  cv::Mat texture(kHeight, kWidth + kDisparity, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(texture, texture, cv::Size(3, 3), 0.7);
  cv::Mat frame;
  cv::hconcat(texture.colRange(0, kWidth), texture.colRange(kDisparity, kDisparity + kWidth),
              frame);
  cv::cvtColor(frame, frame, cv::COLOR_GRAY2BGR);
  return frame;
}

struct DepthStats {
  double median = 0.0;
  double valid_fraction = 0.0;
};

DepthStats stats(const cv::Mat& depth) {
  std::vector<float> valid;
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      if (depth.at<float>(v, u) > 0.0f) valid.push_back(depth.at<float>(v, u));
    }
  }
  if (valid.empty()) return {};
  std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
  return {valid[valid.size() / 2], static_cast<double>(valid.size()) / depth.total()};
}

void write_kitti_calibration(const std::filesystem::path& path) {
  std::ofstream out(path);
  out << "calib_time: 09-Jan-2012 13:57:47\n"
      << "S_rect_02: 6.400000e+02 4.800000e+02\n"
      << "P_rect_02: 500 0 319.5 0 0 500 239.5 0 0 0 1 0\n"
      << "S_rect_03: 640 480\n"
      << "P_rect_03: 500 0 319.5 -60 0 500 239.5 0 0 0 1 0\n";  // -f B
}

void write_opencv_calibration(const std::filesystem::path& path, bool with_t) {
  cv::FileStorage fs(path.string(), cv::FileStorage::WRITE);
  const cv::Mat m = (cv::Mat_<double>(3, 3) << kFocal, 0, 319.5, 0, kFocal, 239.5, 0, 0, 1);
  fs << "M1" << m << "D1" << cv::Mat::zeros(1, 5, CV_64F);
  fs << "M2" << m << "D2" << cv::Mat::zeros(1, 5, CV_64F);
  fs << "R" << cv::Mat::eye(3, 3, CV_64F);
  if (with_t) fs << "T" << (cv::Mat_<double>(3, 1) << -kBaseline, 0, 0);
  fs << "image_width" << kWidth << "image_height" << kHeight;
}

TEST(StereoDepth, PlaneFromKittiCalibration) {
  const auto path = scratch("calib_cam_to_cam.txt");
  write_kitti_calibration(path);
  const StereoCalibration calib = StereoCalibration::load_kitti(path);
  EXPECT_FALSE(calib.needs_remap());
  EXPECT_NEAR(calib.baseline_m, kBaseline, 1e-6);
  EXPECT_EQ(calib.half_size, cv::Size(kWidth, kHeight));

  StereoDepth stereo(calib);
  const cv::Mat frame = side_by_side_plane();
  const StereoFrame out = stereo.compute(frame);
  ASSERT_EQ(out.depth.type(), CV_32FC1);
  ASSERT_EQ(out.depth.size(), cv::Size(kWidth, kHeight));
  // Already rectified: the segmenter sees the left half unchanged.
  EXPECT_EQ(cv::norm(out.left_bgr, frame.colRange(0, kWidth), cv::NORM_INF), 0.0);
  EXPECT_EQ(out.intrinsics.fx, 500.0f);
  EXPECT_TRUE(out.left_from_rectified.isIdentity());
  const DepthStats s = stats(out.depth);
  EXPECT_NEAR(s.median, kPlaneZ, 0.02 * kPlaneZ);
  EXPECT_GT(s.valid_fraction, 0.5);
}

TEST(StereoDepth, PlaneFromOpenCvCalibration) {
  const auto path = scratch("stereo.yml");
  write_opencv_calibration(path, true);
  const StereoCalibration calib = StereoCalibration::from_opencv_yaml(path);
  EXPECT_TRUE(calib.needs_remap());
  EXPECT_NEAR(calib.baseline_m, kBaseline, 1e-5);
  EXPECT_TRUE(calib.left_from_rectified.isIdentity(1e-6f));

  StereoDepth stereo(calib);
  const StereoFrame out = stereo.compute(side_by_side_plane());
  ASSERT_EQ(out.left_bgr.type(), CV_8UC3);
  ASSERT_EQ(out.left_bgr.size(), cv::Size(kWidth, kHeight));
  const DepthStats s = stats(out.depth);
  EXPECT_NEAR(s.median, kPlaneZ, 0.02 * kPlaneZ);
  EXPECT_GT(s.valid_fraction, 0.5);
}

TEST(StereoDepth, FrameOfWrongSizeNamesBothSizes) {
  const auto path = scratch("calib_cam_to_cam.txt");
  write_kitti_calibration(path);
  StereoDepth stereo(StereoCalibration::load_kitti(path));
  try {
    stereo.compute(cv::Mat(kHeight - 1, 2 * kWidth, CV_8UC3));
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("1280x479"), HasSubstr("1280x480")));
  }
  EXPECT_THROW(stereo.compute(cv::Mat(kHeight, kWidth, CV_8UC3)), std::invalid_argument);
}

TEST(StereoDepth, RejectsBadOptions) {
  StereoCalibration calib;
  StereoOptions options;
  options.block_size = 4;
  try {
    StereoDepth stereo(calib, options);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("block_size"));
  }
  options = StereoOptions{};
  options.num_disparities = 100;
  EXPECT_THROW(StereoDepth(calib, options), std::invalid_argument);
}

TEST(StereoCalibration, ErrorsNameFileAndKey) {
  const auto yaml = scratch("no_t.yml");
  write_opencv_calibration(yaml, false);
  try {
    StereoCalibration::from_opencv_yaml(yaml);
    FAIL() << "no error";
  } catch (const CalibrationError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr(yaml.string()), HasSubstr("'T'")));
  }
  const KittiCalibText text("P_rect_02: 500 0 319.5 0 0 500 239.5 0 0 0 1 0\n", "cam.txt");
  try {
    StereoCalibration::from_kitti(text);
    FAIL() << "no error";
  } catch (const CalibrationError& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("cam.txt"), HasSubstr("'P_rect_03'")));
  }
  EXPECT_THROW(StereoCalibration::from_opencv_yaml(scratch("absent.yml")), CalibrationError);
}

TEST(StereoCalibration, LoadsRealKittiCalibration) {
  const StereoCalibration calib = StereoCalibration::load_kitti(
      std::filesystem::path(SEMAP_SHARED_DATA_DIR) / "kitti/2011_09_26/calib_cam_to_cam.txt");
  EXPECT_EQ(calib.half_size, cv::Size(1242, 375));
  EXPECT_NEAR(calib.rectified.fx, 721.5377f, 1e-3f);
  EXPECT_NEAR(calib.rectified.cy, 172.8540f, 1e-3f);
  // (44.85728 - -339.5242) / 721.5377
  EXPECT_NEAR(calib.baseline_m, 0.532719f, 1e-5f);
}

}  // namespace
}  // namespace semap::perception
