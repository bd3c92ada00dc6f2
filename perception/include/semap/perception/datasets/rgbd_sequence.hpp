#pragma once

// An RGB-D dataset as the readers deliver it (read_tum, read_redwood): colour and depth files
// paired, each pair with its camera pose, and the depth images' scale.
#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <vector>

#include "semap/perception/datasets/dataset.hpp"
#include "semap/perception/depth_projection.hpp"

namespace semap::perception::datasets {

struct RgbdFrame {
  double stamp_s = 0.0;  // the colour image's stamp, in the dataset's clock
  std::filesystem::path colour;
  std::filesystem::path depth;  // 16-bit single-channel PNG: read_depth_metres
  // Camera = optical frame (x right, y down, z forward); world = the frame the dataset's poses
  // are given in, unchanged.
  Eigen::Isometry3d world_from_camera = Eigen::Isometry3d::Identity();
};

struct RgbdSequence {
  std::vector<RgbdFrame> frames;  // in stamp order; only frames with both files and a pose
  std::optional<PinholeIntrinsics> intrinsics;  // when the dataset ships them
  double depth_units_per_metre = 1000.0;        // raw depth value of one metre
  std::vector<InputProblem> problems;           // everything skipped, in the order found
};

}  // namespace semap::perception::datasets
