#pragma once

// The text files of a TUM RGB-D sequence, parsed one line at a time: the parts of read_tum
// (tum.hpp), public for tests and fuzzing. A line that does not parse is an InputProblem named
// "name:line" and is left out; '#' comment lines and blank lines are skipped.
#include <Eigen/Geometry>
#include <string>
#include <string_view>
#include <vector>

#include "semap/perception/datasets/dataset.hpp"

namespace semap::perception::datasets {

// rgb.txt, depth.txt: `timestamp filename` per line, the file relative to the sequence folder.
struct TumListEntry {
  double stamp_s = 0.0;
  std::string file;
  int line = 0;
};
struct TumList {
  std::vector<TumListEntry> entries;  // in file order
  std::vector<InputProblem> problems;
};
TumList parse_tum_list(std::string_view text, const std::string& name);

// groundtruth.txt: `timestamp tx ty tz qx qy qz qw` per line, the colour camera's optical frame
// in the motion-capture world. A quaternion whose norm is not 1 within 1e-2 is a problem (the
// files give four decimals); others are normalised.
struct TumPose {
  double stamp_s = 0.0;
  Eigen::Isometry3d world_from_camera = Eigen::Isometry3d::Identity();
};
struct TumGroundTruth {
  std::vector<TumPose> poses;  // in stamp order
  std::vector<InputProblem> problems;
};
TumGroundTruth parse_tum_groundtruth(std::string_view text, const std::string& name);

}  // namespace semap::perception::datasets
