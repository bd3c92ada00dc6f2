#include "semap/perception/depth_projection.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>
#include <opencv2/core.hpp>

#include "semap/perception/depth_cloud.hpp"
#include "semap/perception/synthetic_depth_camera.hpp"

namespace semap::perception {
namespace {

TEST(PinholeIntrinsics, FromFov) {
  const auto k = PinholeIntrinsics::from_fov(100, 50, std::numbers::pi_v<float> / 2);
  EXPECT_NEAR(k.fx, 50.0f, 1e-4f);
  EXPECT_NEAR(k.cx, 49.5f, 1e-6f);
  EXPECT_NEAR(k.cy, 24.5f, 1e-6f);
}

TEST(OpticalToFlu, MapsAxes) {
  const Eigen::Matrix3f r = optical_to_flu();
  EXPECT_TRUE((r * Eigen::Vector3f::UnitZ()).isApprox(Eigen::Vector3f::UnitX()));
  EXPECT_TRUE((r * Eigen::Vector3f::UnitX()).isApprox(-Eigen::Vector3f::UnitY()));
  EXPECT_TRUE((r * Eigen::Vector3f::UnitY()).isApprox(-Eigen::Vector3f::UnitZ()));
  EXPECT_NEAR(r.determinant(), 1.0f, 1e-6f);
}

// The rendered class image as a segmenter's hard labels (what a perfect segmenter gives).
Segmentation perfect_segmentation(const LabeledDepthImage& image, const PinholeIntrinsics& k) {
  Segmentation seg;
  seg.num_classes = 4;
  seg.labels = cv::Mat(k.height, k.width, CV_16UC1);
  std::copy(image.labels.begin(), image.labels.end(), seg.labels.begin<std::uint16_t>());
  seg.labels.setTo(kNoLabel, seg.labels == 0);  // no hit: sky
  seg.confidence = cv::Mat(k.height, k.width, CV_32FC1, cv::Scalar(1.0f));
  return seg;
}

// Rendering a known world and back-projecting must land every point on the surface it hit.
TEST(SyntheticDepthCamera, BackProjectsOntoTheRenderedSurfaces) {
  SyntheticScene scene;
  scene.add_box(Eigen::Vector3f(6, -20, 0), Eigen::Vector3f(7, 20, 5));  // a wall at x = 6
  const auto k = PinholeIntrinsics::from_fov(64, 48, std::numbers::pi_v<float> / 2);
  const SyntheticDepthCamera camera(k, 30.0f);
  Eigen::Isometry3f world_from_optical = Eigen::Isometry3f::Identity();
  world_from_optical.linear() = optical_to_flu();
  world_from_optical.translation() = Eigen::Vector3f(0, 0, 1.5f);
  const auto image = camera.render(scene, world_from_optical, common::Stamp(42));
  EXPECT_EQ(image.stamp, common::Stamp(42));
  const cv::Mat depth(k.height, k.width, CV_32FC1, const_cast<float*>(image.depth.data()));
  PointOptions options;
  options.max_range = 30.0f;
  DropCounts drops;
  const auto cloud = cloud_from_depth(depth, perfect_segmentation(image, k), k, world_from_optical,
                                      options, drops);
  ASSERT_GT(cloud.size(), 1000u);
  EXPECT_EQ(cloud.size() + drops.total(), static_cast<std::size_t>(k.width * k.height));
  EXPECT_TRUE(cloud.origin.isApprox(Eigen::Vector3f(0, 0, 1.5f)));
  int wall = 0;
  int ground = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto& p = cloud.points[i];
    if (cloud.labels[i] == scene.labels().building) {
      EXPECT_NEAR(p.x(), 6.0f, 1e-3f);
      ++wall;
    } else {
      EXPECT_EQ(cloud.labels[i], scene.labels().ground);
      EXPECT_NEAR(p.z(), 0.0f, 1e-3f);
      ++ground;
    }
  }
  EXPECT_GT(wall, 0);
  EXPECT_GT(ground, 0);
}

}  // namespace
}  // namespace semap::perception
