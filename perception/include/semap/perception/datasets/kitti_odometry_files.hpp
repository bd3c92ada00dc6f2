#pragma once

// The text files of a KITTI odometry sequence, one row per scan: the parts of
// read_kitti_odometry (kitti_odometry.hpp), public for tests and fuzzing. Row i is line i + 1,
// so a line that does not parse (an InputProblem "name:line") costs its scan only.
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "semap/perception/datasets/dataset.hpp"

namespace semap::perception::datasets {

// poses.txt / poses/SS.txt: 12 numbers per line, a row-major 3x4 pose of camera 0 in the
// first camera-0 frame. A row whose 3x3 block is not a rotation has no pose.
struct KittiPoses {
  std::vector<std::optional<Eigen::Isometry3d>> rows;
  std::vector<InputProblem> problems;
};
KittiPoses parse_kitti_poses(std::string_view text, const std::string& name);

// times.txt: one stamp in seconds per line.
struct KittiTimes {
  std::vector<std::optional<double>> rows;
  std::vector<InputProblem> problems;
};
KittiTimes parse_kitti_times(std::string_view text, const std::string& name);

}  // namespace semap::perception::datasets
