#include "semap/perception/synthetic_scene.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace semap::perception {
namespace {

TEST(SyntheticScene, GroundHitAtExpectedRange) {
  SyntheticScene scene;
  // From 2 m up, 45 degrees down: the ground is 2 * sqrt(2) away.
  const Eigen::Vector3f dir = Eigen::Vector3f(1, 0, -1).normalized();
  const auto hit = scene.cast(Eigen::Vector3f(0, 0, 2), dir, 100.0f);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 2.0f * std::sqrt(2.0f), 1e-5f);
  EXPECT_EQ(hit->label, scene.labels().ground);
  EXPECT_FALSE(scene.cast(Eigen::Vector3f(0, 0, 2), Eigen::Vector3f(1, 0, 0), 100.0f));
  EXPECT_FALSE(scene.cast(Eigen::Vector3f(0, 0, 2), dir, 2.0f));  // beyond max range
}

TEST(SyntheticScene, NearestPrimitiveWins) {
  SyntheticScene scene;
  scene.add_box(Eigen::Vector3f(10, -1, 0), Eigen::Vector3f(12, 1, 3));
  scene.add_cylinder(Eigen::Vector2f(5, 0), 0.5f, 4.0f);
  const auto hit = scene.cast(Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(1, 0, 0), 50.0f);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 4.5f, 1e-5f);
  EXPECT_EQ(hit->label, scene.labels().pole);
  // Above the cylinder (height 4) the box behind it is seen, up to its height 3.
  const auto over = scene.cast(Eigen::Vector3f(0, 0, 2.5f), Eigen::Vector3f(1, 0, 0), 50.0f);
  ASSERT_TRUE(over);
  EXPECT_NEAR(over->range, 4.5f, 1e-5f);
  const auto high = scene.cast(Eigen::Vector3f(0, 3, 2.5f), Eigen::Vector3f(1, 0, 0), 50.0f);
  EXPECT_FALSE(high);
  const auto box = scene.cast(Eigen::Vector3f(0, 0.8f, 1), Eigen::Vector3f(1, 0, 0), 50.0f);
  ASSERT_TRUE(box);
  EXPECT_NEAR(box->range, 10.0f, 1e-5f);
  EXPECT_EQ(box->label, scene.labels().building);
}

TEST(SyntheticScene, AroundPathKeepsCorridorClear) {
  std::vector<Eigen::Vector3d> path;
  for (int i = 0; i < 500; ++i) path.emplace_back(0.1 * i, 0.0, 0.0);
  const auto scene = SyntheticScene::around_path(path, 4.0f, 40, 3);
  EXPECT_EQ(scene.boxes().size() + scene.cylinders().size(), 40u);
  // Driving along the path at sensor height never hits anything but the ground.
  for (const auto& p : path) {
    const auto hit =
        scene.cast(p.cast<float>() + Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(0, 1, 0), 3.5f);
    EXPECT_FALSE(hit) << "obstacle inside the corridor near x=" << p.x();
  }
  // Same seed, same world.
  const auto again = SyntheticScene::around_path(path, 4.0f, 40, 3);
  ASSERT_EQ(again.cylinders().size(), scene.cylinders().size());
  EXPECT_EQ(again.cylinders().front().center, scene.cylinders().front().center);
}

}  // namespace
}  // namespace semap::perception
