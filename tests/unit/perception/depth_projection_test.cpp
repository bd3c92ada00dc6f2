#include "semap/perception/depth_projection.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numbers>
#include <opencv2/core.hpp>

#include "semap/perception/depth_cloud.hpp"
#include "semap/perception/sim_classes.hpp"
#include "semap/sim/camera.hpp"
#include "semap/sim/world.hpp"

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

// The simulated camera's true classes as a segmenter's hard labels (a perfect segmenter).
Segmentation perfect_segmentation(const sim::SimFrame& frame) {
  Segmentation seg;
  seg.num_classes = kSimMapClasses;
  seg.labels.create(frame.labels.size(), CV_16UC1);
  for (int v = 0; v < frame.labels.rows; ++v) {
    for (int u = 0; u < frame.labels.cols; ++u) {
      seg.labels.at<std::uint16_t>(v, u) = sim_map_class(frame.labels.at<std::uint8_t>(v, u));
    }
  }
  seg.confidence = cv::Mat(frame.labels.size(), CV_32FC1, cv::Scalar(1.0f));
  return seg;
}

// Back-projecting the simulated camera's depth must put each labelled pixel on the surface of
// its class in the world it rendered (to within the depth noise).
TEST(BackProjection, LandsOnTheRenderedWorld) {
  std::vector<Eigen::Vector3d> path;
  for (int i = 0; i <= 40; ++i) path.emplace_back(i, 0.0, 0.0);
  const sim::SimWorld world(path);
  sim::SimCameraOptions options;
  options.intrinsics = PinholeIntrinsics::from_fov(160, 120, std::numbers::pi_v<float> / 2);
  Eigen::Isometry3f world_from_optical = Eigen::Isometry3f::Identity();
  world_from_optical.linear() = optical_to_flu();
  world_from_optical.translation() = Eigen::Vector3f(2, 0, 1.5f);
  const sim::SimFrame frame = sim::SimCamera(options).render(world, world_from_optical, 0);
  PointOptions points;
  points.max_range = 15.0f;
  DropCounts drops;
  const auto cloud = cloud_from_depth(frame.depth_m, perfect_segmentation(frame),
                                      options.intrinsics, world_from_optical, points, drops);
  ASSERT_GT(cloud.size(), 5000u);
  EXPECT_EQ(cloud.size() + drops.total(), static_cast<std::size_t>(160 * 120));
  EXPECT_TRUE(cloud.origin.isApprox(Eigen::Vector3f(2, 0, 1.5f)));
  std::size_t agree = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (world.class_at(cloud.points[i], 0.15f) == cloud.labels[i]) ++agree;
  }
  // Depth noise (sigma 0.23 m at 15 m) and class borders account for the rest.
  EXPECT_GT(static_cast<double>(agree) / static_cast<double>(cloud.size()), 0.9);
}

}  // namespace
}  // namespace semap::perception
