#include "semap/fusion/fusion_config.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace semap::fusion {
namespace {

MapFusionConfig read(const std::string& body) {
  const auto root = common::ConfigSection::load_string("fusion:\n" + body, "fusion.yaml");
  return read_fusion_config(root.section("fusion"));
}

TEST(FusionConfig, ReadsRobotsTransformsAndShape) {
  const auto cfg = read(
      "  robots: [robot1, robot2]\n"
      "  transforms: { robot2: [10, -2, 0.5, 0, 0, 1.5707963267948966] }\n"
      "  method: csm\n  prior: 0.01\n  resolution: 0.2\n  block_cells: 4\n  num_classes: 3\n"
      "  output: team\n  publish_hz: 5\n");
  ASSERT_EQ(cfg.robots.size(), 2u);
  EXPECT_EQ(cfg.robots[0].ns, "robot1");
  EXPECT_TRUE(cfg.robots[0].T_fused_robot.isApprox(Eigen::Isometry3d::Identity()));
  // Yaw 90 degrees: the robot's x axis is the fused y axis, then the shift.
  const Eigen::Vector3d p = cfg.robots[1].T_fused_robot * Eigen::Vector3d(1, 0, 0);
  EXPECT_NEAR(p.x(), 10.0, 1e-12);
  EXPECT_NEAR(p.y(), -1.0, 1e-12);
  EXPECT_NEAR(p.z(), 0.5, 1e-12);
  EXPECT_EQ(cfg.method, mapping::MapMethod::kCsm);
  EXPECT_DOUBLE_EQ(cfg.prior, 0.01);
  EXPECT_EQ(cfg.description.block_cells, 4);
  EXPECT_EQ(cfg.description.num_classes, 3);
  EXPECT_EQ(cfg.output.ns, "team");
  EXPECT_DOUBLE_EQ(cfg.output.blocks_hz, 5.0);
}

TEST(FusionConfig, RollPitchYawFollowRosFixedAxes) {
  const auto T = transform_from_xyz_rpy({0, 0, 0, M_PI / 2, 0, M_PI / 2});
  // Roll first (y -> z), then yaw (x -> y): the robot's y axis ends up on the fused z axis.
  EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE((T.linear() * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  EXPECT_THROW(transform_from_xyz_rpy({1, 2, 3}), std::invalid_argument);
  EXPECT_THROW(transform_from_xyz_rpy({0, 0, 0, 0, 0, NAN}), std::invalid_argument);
}

TEST(FusionConfig, RejectsMistakesNamingTheKey) {
  const std::string shape = "  num_classes: 4\n";
  const auto message = [&](const std::string& body) -> std::string {
    try {
      read(body + shape);
    } catch (const common::ConfigError& e) {
      return e.what();
    }
    return "accepted";
  };
  EXPECT_NE(
      message("  robots: [a, b]\n  transforms: { c: [0, 0, 0, 0, 0, 0] }\n").find("transforms.c"),
      std::string::npos);
  EXPECT_NE(message("  robots: [a, b]\n  transforms: { b: [1, 2] }\n").find("transforms.b"),
            std::string::npos);
  EXPECT_NE(message("  robots: [a, a]\n").find("listed twice"), std::string::npos);
  EXPECT_NE(message("  robots: [a, fused]\n").find("output namespace"), std::string::npos);
  EXPECT_NE(message("  robots: [a]\n  block_cells: 6\n").find("fusion.block_cells"),
            std::string::npos);
  EXPECT_NE(message("  robots: [a]\n  method: logodds\n").find("fusion.method"), std::string::npos);
  EXPECT_NE(message("  robots: [a]\n  free_class: 0\n").find("unknown key"), std::string::npos);
  EXPECT_NE(message("  robots: [a]\n  class_names: [x]\n").find("class_names"), std::string::npos);
}

}  // namespace
}  // namespace semap::fusion
