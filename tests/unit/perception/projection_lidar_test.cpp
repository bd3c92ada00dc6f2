#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <vector>

#include "projection_fixtures.hpp"
#include "semap/perception/lidar_projection.hpp"

namespace semap::perception {
namespace {

using fixtures::label_at;
using fixtures::make_segmentation;
using fixtures::probability_at;
using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr int kClasses = 6;

// A 64x48 camera with f = 50, 0.06 m left of rectified camera 0 like KITTI's camera 2
// (P[0,3] = f * 0.06), a
// rectifying rotation of 2 degrees about y and KITTI's Velodyne axes (x forward, y left, z up).
constexpr const char* kCamToCam =
    "calib_time: 09-Jan-2012 13:57:47\n"
    "S_rect_02: 64 48\n"
    "P_rect_02: 50 0 31.5 3 0 50 23.5 0 0 0 1 0\n"
    "R_rect_00: 0.99939083 0 0.0348995 0 1 0 -0.0348995 0 0.99939083\n";
constexpr const char* kVeloToCam =
    "R: 0 -1 0 0 0 -1 1 0 0\n"
    "T: 0.1 -0.2 -0.3\n";

KittiCameraCalibration hand_made() {
  return KittiCameraCalibration::from_text(KittiCalibText(kCamToCam, "cam_to_cam"),
                                           KittiCalibText(kVeloToCam, "velo_to_cam"));
}

// The lidar point seen at pixel (u, v), depth z in front of camera 2, worked back through the
// same numbers: camera 2 -> rectified camera 0 -> camera 0 -> Velodyne.
Eigen::Vector3f lidar_point_at(double u, double v, double z) {
  const Eigen::Vector3d cam2((u - 31.5) / 50.0 * z, (v - 23.5) / 50.0 * z, z);
  const Eigen::Vector3d rect0 = cam2 - Eigen::Vector3d(0.06, 0, 0);
  Eigen::Matrix3d r_rect;
  r_rect << 0.99939083, 0, 0.0348995, 0, 1, 0, -0.0348995, 0, 0.99939083;
  const Eigen::Vector3d cam0 = r_rect.transpose() * rect0;
  Eigen::Matrix3d r;
  r << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  return (r.transpose() * (cam0 - Eigen::Vector3d(0.1, -0.2, -0.3))).cast<float>();
}

Eigen::Isometry3f lidar_on_roof() {
  Eigen::Isometry3f body_from_lidar = Eigen::Isometry3f::Identity();
  body_from_lidar.translation() = Eigen::Vector3f(-0.3f, 0.0f, 1.7f);
  body_from_lidar.linear() = Eigen::AngleAxisf(0.1f, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  return body_from_lidar;
}

TEST(LabelLidarPoints, PointsTakeTheLabelOfTheirPixel) {
  const KittiCameraCalibration calib = hand_made();
  const Segmentation seg = make_segmentation(64, 48, kClasses, false);
  // Pixel centres, pixel edges within 0.5 px and the image corners.
  const std::vector<Eigen::Vector3d> at = {{10, 20, 4.0},   {0, 0, 7.0},   {63, 47, 2.5},
                                           {31.4, 23.6, 9}, {5.45, 40, 3}, {62.6, 0.4, 12}};
  const std::vector<Eigen::Vector2i> pixel = {{10, 20}, {0, 0},  {63, 47},
                                              {31, 24}, {5, 40}, {63, 0}};
  std::vector<Eigen::Vector3f> points;
  for (const auto& p : at) points.push_back(lidar_point_at(p.x(), p.y(), p.z()));
  const Eigen::Isometry3f body_from_lidar = lidar_on_roof();
  DropCounts drops;
  const auto cloud = label_lidar_points(points, seg, calib, body_from_lidar, PointOptions{}, drops);

  ASSERT_EQ(cloud.size(), points.size());
  EXPECT_EQ(drops.total(), 0u);
  EXPECT_EQ(cloud.num_classes, kClasses);
  EXPECT_TRUE(cloud.origin.isApprox(body_from_lidar.translation()));
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(cloud.labels[i], label_at(pixel[i].x(), pixel[i].y(), kClasses)) << "point " << i;
    EXPECT_TRUE(cloud.points[i].isApprox(body_from_lidar * points[i], 1e-6f));
  }
}

TEST(LabelLidarPoints, CountsEveryDroppedPoint) {
  Segmentation seg = make_segmentation(64, 48, kClasses, false);
  seg.labels.at<std::uint16_t>(10, 10) = kNoLabel;
  seg.confidence.at<float>(11, 11) = 0.2f;
  const std::vector<Eigen::Vector3f> points = {
      lidar_point_at(30, 30, 5.0),                                      // kept
      lidar_point_at(30, 30, -5.0),                                     // behind the camera
      lidar_point_at(-0.6, 10, 5.0),                                    // left of the image
      lidar_point_at(20, 47.6, 5.0),                                    // below the image
      lidar_point_at(10, 10, 5.0),                                      // kNoLabel
      lidar_point_at(11, 11, 5.0),                                      // low confidence
      lidar_point_at(30, 30, 40.0),                                     // beyond max_range
      Eigen::Vector3f(std::numeric_limits<float>::quiet_NaN(), 0, 0)};  // no return
  PointOptions options;
  options.max_range = 30.0f;
  options.min_confidence = 0.5f;
  DropCounts drops;
  const auto cloud = label_lidar_points(points, seg, hand_made(), lidar_on_roof(), options, drops);
  EXPECT_EQ(cloud.size(), 1u);
  EXPECT_EQ(drops.out_of_image, 3u);
  EXPECT_EQ(drops.no_label, 1u);
  EXPECT_EQ(drops.low_confidence, 1u);
  EXPECT_EQ(drops.out_of_range, 1u);
  EXPECT_EQ(drops.no_depth, 1u);
}

TEST(LabelLidarPoints, CopiesSoftLabels) {
  const Segmentation seg = make_segmentation(64, 48, kClasses, true);
  const std::vector<Eigen::Vector3f> points = {lidar_point_at(7, 9, 3), lidar_point_at(50, 2, 6)};
  DropCounts drops;
  auto cloud = label_lidar_points(points, seg, hand_made(), lidar_on_roof(), PointOptions{}, drops);
  ASSERT_EQ(cloud.probabilities.size(), 2u * kClasses);
  EXPECT_TRUE(cloud.labels.empty());
  for (int c = 0; c < kClasses; ++c) {
    EXPECT_EQ(cloud.probabilities[c], probability_at(7, 9, c, kClasses));
    EXPECT_EQ(cloud.probabilities[kClasses + c], probability_at(50, 2, c, kClasses));
  }
  PointOptions hard;
  hard.soft_labels = false;
  cloud = label_lidar_points(points, seg, hand_made(), lidar_on_roof(), hard, drops);
  EXPECT_FALSE(cloud.has_probabilities());
  EXPECT_EQ(cloud.labels,
            (std::vector<std::uint16_t>{label_at(7, 9, kClasses), label_at(50, 2, kClasses)}));
}

TEST(LabelLidarPoints, SegmentationOfAnotherSizeNamesBoth) {
  DropCounts drops;
  try {
    label_lidar_points({}, make_segmentation(32, 48, kClasses, false), hand_made(),
                       Eigen::Isometry3f::Identity(), PointOptions{}, drops);
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), AllOf(HasSubstr("32x48"), HasSubstr("64x48")));
  }
}

TEST(KittiCameraCalibration, LoadsRealFiles) {
  const auto dir = std::filesystem::path(SEMAP_SHARED_DATA_DIR) / "kitti/2011_09_26";
  const auto calib =
      KittiCameraCalibration::load(dir / "calib_cam_to_cam.txt", dir / "calib_velo_to_cam.txt");
  EXPECT_EQ(calib.image_size, cv::Size(1242, 375));
  EXPECT_DOUBLE_EQ(calib.p_rect(0, 0), 721.5377);
  EXPECT_DOUBLE_EQ(calib.p_rect(0, 3), 44.85728);
  EXPECT_DOUBLE_EQ(calib.r_rect(0, 1), 9.837760e-03);
  EXPECT_DOUBLE_EQ(calib.cam_from_lidar.linear()(0, 0), 7.533745e-03);
  EXPECT_DOUBLE_EQ(calib.cam_from_lidar.translation().z(), -2.717806e-01);
  EXPECT_DOUBLE_EQ(calib.cam_from_lidar.translation().y(), -7.631618e-02);
  // A point 15 m ahead of the Velodyne lands near the principal point (609.6, 172.9), a few
  // pixels below it: the Velodyne sits above the cameras. Expected values worked by hand.
  DropCounts drops;
  const std::vector<Eigen::Vector3f> ahead = {Eigen::Vector3f(15, 0, 0)};
  const auto cloud = label_lidar_points(ahead, make_segmentation(1242, 375, kClasses, false), calib,
                                        Eigen::Isometry3f::Identity(), PointOptions{}, drops);
  EXPECT_EQ(cloud.size(), 1u);
  const Eigen::Vector3f y = calib.image_from_lidar() * Eigen::Vector4f(15, 0, 0, 1);
  EXPECT_NEAR(y.x() / y.z(), 612.5f, 0.5f);
  EXPECT_NEAR(y.y() / y.z(), 176.8f, 0.5f);

  const auto camera0 =
      KittiCameraCalibration::load(dir / "calib_cam_to_cam.txt", dir / "calib_velo_to_cam.txt", 0);
  EXPECT_EQ(camera0.p_rect(0, 3), 0.0);
  EXPECT_THROW(
      KittiCameraCalibration::load(dir / "calib_cam_to_cam.txt", dir / "calib_velo_to_cam.txt", 4),
      std::invalid_argument);
}

// More points through the real 2011_09_26 calibration (semap-dataset kitti-raw's projection).
// Pixels worked out apart from this code: P_rect_02 * R_rect_00 * [R T] of the files, multiplied
// out in plain Python. (6, 3, -1.7) lands below the image (v = 389.9 > 375), (-5, 0, 0) behind it.
TEST(KittiCameraCalibration, RealCalibrationPixels) {
  const auto dir = std::filesystem::path(SEMAP_SHARED_DATA_DIR) / "kitti/2011_09_26";
  const auto calib =
      KittiCameraCalibration::load(dir / "calib_cam_to_cam.txt", dir / "calib_velo_to_cam.txt");
  struct Case {
    Eigen::Vector3f lidar;
    float u, v, depth;
  };
  const std::vector<Case> cases = {{{15, 0, 0}, 612.53f, 176.84f, 14.73f},
                                   {{10, 2, -1.5f}, 466.61f, 287.98f, 9.715f},
                                   {{20, -5, 1}, 794.19f, 139.25f, 19.739f}};
  const Eigen::Matrix<float, 3, 4> m = calib.image_from_lidar();
  std::vector<Eigen::Vector3f> points;
  for (const Case& c : cases) {
    const Eigen::Vector3f y = m * c.lidar.homogeneous();
    EXPECT_NEAR(y.x() / y.z(), c.u, 0.02f);
    EXPECT_NEAR(y.y() / y.z(), c.v, 0.02f);
    EXPECT_NEAR(y.z(), c.depth, 0.002f);
    points.push_back(c.lidar);
  }
  points.emplace_back(6.0f, 3.0f, -1.7f);
  points.emplace_back(-5.0f, 0.0f, 0.0f);
  DropCounts drops;
  PointOptions options;
  options.max_range = 50.0f;
  const auto cloud = label_lidar_points(points, make_segmentation(1242, 375, kClasses, false),
                                        calib, Eigen::Isometry3f::Identity(), options, drops);
  EXPECT_EQ(cloud.size(), 3u);
  EXPECT_EQ(drops.out_of_image, 2u);
}

std::string error_of(std::string_view cam_to_cam, std::string_view velo_to_cam) {
  try {
    KittiCameraCalibration::from_text(KittiCalibText(cam_to_cam, "cam.txt"),
                                      KittiCalibText(velo_to_cam, "velo.txt"));
  } catch (const CalibrationError& e) {
    return e.what();
  }
  return "no error";
}

TEST(KittiCameraCalibration, MalformedTextNamesFileAndKey) {
  const std::string cam(kCamToCam);
  const std::string velo(kVeloToCam);
  EXPECT_THAT(error_of("S_rect_02: 64 48\nP_rect_02: 50 0 31.5 3 0 50 23.5 0 0 0 1 0\n", velo),
              AllOf(HasSubstr("cam.txt"), HasSubstr("'R_rect_00'"), HasSubstr("missing")));
  EXPECT_THAT(error_of(cam + "P_rect_02: 1 2 3\n", velo),
              AllOf(HasSubstr("cam.txt"), HasSubstr("'P_rect_02'"), HasSubstr("given twice")));
  EXPECT_THAT(error_of("S_rect_02: 64 48\nP_rect_02: 50 0 31.5 3 0 50 23.5 0 0 0 1\n", velo),
              AllOf(HasSubstr("cam.txt"), HasSubstr("'P_rect_02'"),
                    HasSubstr("expected 12 numbers, got 11")));
  EXPECT_THAT(
      error_of(cam, "R: 0 -1 0 0 0 -1 1 0 zero\nT: 0 0 0\n"),
      AllOf(HasSubstr("velo.txt"), HasSubstr("'R'"), HasSubstr("value 9"), HasSubstr("'zero'")));
  EXPECT_THAT(error_of(cam, "R: 0 -1 0 0 0 -1 1 0 0\nT: 0 0 nan\n"),
              AllOf(HasSubstr("velo.txt"), HasSubstr("'T'"), HasSubstr("not a finite number")));
  EXPECT_THAT(error_of(cam, "R: 0 -1 0 0 0 -1 1 0 0\nT 0 0 0\n"),
              AllOf(HasSubstr("velo.txt"), HasSubstr("line 2")));
  EXPECT_THAT(error_of("S_rect_02: 64.5 48\n" + cam.substr(cam.find("P_rect")), velo),
              AllOf(HasSubstr("cam.txt"), HasSubstr("'S_rect_02'")));
  try {
    KittiCalibText::read("/nonexistent/calib_velo_to_cam.txt");
    FAIL() << "no error";
  } catch (const CalibrationError& e) {
    EXPECT_THAT(e.what(), HasSubstr("/nonexistent/calib_velo_to_cam.txt"));
  }
}

}  // namespace
}  // namespace semap::perception
