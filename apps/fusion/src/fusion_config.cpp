#include "semap/fusion/fusion_config.hpp"

#include <bit>
#include <cmath>
#include <set>
#include <stdexcept>

namespace semap::fusion {

Eigen::Isometry3d transform_from_xyz_rpy(const std::vector<double>& v) {
  if (v.size() != 6) {
    throw std::invalid_argument("a transform needs 6 values x, y, z, roll, pitch, yaw, got " +
                                std::to_string(v.size()));
  }
  for (double x : v) {
    if (!std::isfinite(x)) throw std::invalid_argument("a transform value is not finite");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(v[5], Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(v[4], Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(v[3], Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return T;
}

MapFusionConfig read_fusion_config(const common::ConfigSection& f) {
  const auto fail = [&](const std::string& key, const std::string& what) {
    throw common::ConfigError(f.file() + ": key '" + f.path() + "." + key + "': " + what);
  };
  MapFusionConfig cfg;
  cfg.output.ns = f.get<std::string>("output", "fused");
  cfg.output.frame_id = f.get<std::string>("frame_id", "map");
  cfg.output.blocks_hz = f.get_in_range("publish_hz", 2.0, 0.01, 100.0);
  cfg.output.cloud_hz = f.get_in_range("cloud_hz", 0.5, 0.0, 100.0);
  cfg.method = mapping::map_method_from_string(f.get_choice("method", "bki", {"bki", "csm"}));
  cfg.prior = f.get_in_range("prior", 0.001, 1e-9, 1e3);
  auto& d = cfg.description;
  d.resolution = static_cast<float>(f.get_in_range("resolution", 0.1, 1e-3, 10.0));
  d.block_cells = static_cast<std::uint16_t>(f.get_in_range("block_cells", 8, 1, 64));
  d.num_classes = static_cast<std::uint16_t>(f.get_in_range("num_classes", 0, 1, 1024));
  d.class_names = f.get<std::vector<std::string>>("class_names", {});
  if (!d.class_names.empty() && d.class_names.size() != d.num_classes) {
    fail("class_names", "needs num_classes (" + std::to_string(d.num_classes) + ") names");
  }
  if (!std::has_single_bit(static_cast<unsigned>(d.block_cells))) {
    fail("block_cells", "must be a power of two like the mapping library's blocks");
  }

  std::set<std::string> seen;
  for (const auto& ns : f.get<std::vector<std::string>>("robots")) {
    if (!seen.insert(ns).second) fail("robots", "'" + ns + "' is listed twice");
    if (ns == cfg.output.ns) fail("robots", "'" + ns + "' is also the output namespace");
    cfg.robots.push_back({ns, Eigen::Isometry3d::Identity()});
  }
  if (cfg.robots.empty()) fail("robots", "no robots to follow");
  const auto transforms = f.section_or_empty("transforms");
  for (auto& robot : cfg.robots) {
    if (!transforms.has(robot.ns)) continue;
    try {
      robot.T_fused_robot = transform_from_xyz_rpy(transforms.get<std::vector<double>>(robot.ns));
    } catch (const std::invalid_argument& e) {
      fail("transforms." + robot.ns, e.what());
    }
  }
  transforms.finish();  // a transform for a robot not in `robots` is a typo
  f.finish();
  return cfg;
}

}  // namespace semap::fusion
