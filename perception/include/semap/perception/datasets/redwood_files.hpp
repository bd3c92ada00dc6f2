#pragma once

// The text files of a Redwood / Open3D RGB-D folder: the parts of read_redwood (redwood.hpp),
// public for tests and fuzzing.
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "semap/perception/datasets/dataset.hpp"
#include "semap/perception/depth_projection.hpp"

namespace semap::perception::datasets {

// A Redwood .log trajectory (http://redwood-data.org/indoor/fileformat.html): per frame a line
// of three numbers (metadata, not used: Open3D, too, takes the frames in file order) and a 4x4
// camera-to-world matrix, one row per line. A line of three fields starts an entry, so one bad
// or missing line costs one frame, not every frame after it. An entry whose lines do not parse,
// whose last row is not 0 0 0 1 or whose rotation is not one has no pose and is a problem
// "name:line: frame i: ..."; a line outside any entry is a problem of its own.
struct RedwoodLogEntry {
  int line = 0;  // of the metadata line
  std::optional<Eigen::Isometry3d> world_from_camera;
};
struct RedwoodLog {
  std::vector<RedwoodLogEntry> entries;  // entry i = frame i
  std::vector<InputProblem> problems;
};
RedwoodLog parse_redwood_log(std::string_view text, const std::string& name);

// rgbd.match: per line a depth file and its colour file, relative to the folder, in that order
// (as Open3D's test data writes it); a line of another shape is a problem.
struct RgbdMatchEntry {
  int line = 0;
  std::string depth;
  std::string colour;
};
struct RgbdMatch {
  std::vector<RgbdMatchEntry> entries;  // entry i = frame i
  std::vector<InputProblem> problems;
};
RgbdMatch parse_rgbd_match(std::string_view text, const std::string& name);

// Open3D's PinholeCameraIntrinsic JSON: "width", "height" and "intrinsic_matrix", the 3x3
// matrix column by column (fx 0 0 0 fy 0 cx cy 1); other keys are ignored. Throws DatasetError
// naming `name` and the line for invalid JSON, a missing key, a size that is not whole positive
// pixels, a skewed matrix or one whose last row is not 0 0 1 (a row-major matrix).
PinholeIntrinsics parse_open3d_intrinsics(std::string_view json, const std::string& name);

}  // namespace semap::perception::datasets
