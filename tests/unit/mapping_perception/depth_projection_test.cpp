#include "semap/mapping/depth_projection.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "semap/mapping/synthetic_depth_camera.hpp"

namespace semap::mapping {
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

// Rendering a known world and back-projecting must land every point on the surface it hit.
TEST(BackProject, RecoversRenderedSurfaces) {
  SyntheticScene scene;
  scene.add_box(Eigen::Vector3f(6, -20, 0), Eigen::Vector3f(7, 20, 5));  // a wall at x = 6
  const auto k = PinholeIntrinsics::from_fov(64, 48, std::numbers::pi_v<float> / 2);
  const SyntheticDepthCamera camera(k, 30.0f);
  Eigen::Isometry3f world_from_optical = Eigen::Isometry3f::Identity();
  world_from_optical.linear() = optical_to_flu();
  world_from_optical.translation() = Eigen::Vector3f(0, 0, 1.5f);
  const auto image = camera.render(scene, world_from_optical, common::Stamp(42));
  const auto cloud = back_project(image, k, world_from_optical, 1, 30.0f);
  ASSERT_GT(cloud.size(), 1000u);
  EXPECT_EQ(cloud.stamp, common::Stamp(42));
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
  // A stride of 2 keeps a quarter of the pixels.
  const auto sparse = back_project(image, k, world_from_optical, 2, 30.0f);
  EXPECT_NEAR(static_cast<double>(sparse.size()), cloud.size() / 4.0, cloud.size() * 0.05);
}

TEST(BackProject, SkipsInvalidDepthAndMismatchedImages) {
  const auto k = PinholeIntrinsics::from_fov(4, 4, 1.0f);
  LabeledDepthImage image;
  image.depth.assign(16, 2.0f);
  image.labels.assign(16, 1);
  image.depth[0] = std::numeric_limits<float>::quiet_NaN();
  image.depth[1] = -1.0f;
  image.depth[2] = 0.0f;
  image.depth[3] = 100.0f;
  EXPECT_EQ(back_project(image, k, Eigen::Isometry3f::Identity(), 1, 50.0f).size(), 12u);
  image.labels.pop_back();
  EXPECT_EQ(back_project(image, k, Eigen::Isometry3f::Identity(), 1, 50.0f).size(), 0u);
}

}  // namespace
}  // namespace semap::mapping
