#pragma once

// Redwood / Open3D RGB-D folders, as Open3D's tutorials and test data lay them out:
// color/*.jpg|png, depth/*.png (16-bit millimetres), a .log trajectory of camera-to-world
// poses, optionally rgbd.match (which colour goes with which depth) and Open3D's intrinsic JSON.
#include <filesystem>

#include "semap/perception/datasets/rgbd_sequence.hpp"
#include "semap/perception/depth_projection.hpp"

namespace semap::perception::datasets {

struct RedwoodOptions {
  // The frames' poses. Empty: <dir>/odometry.log, and without it an error. A folder may hold
  // other .log files that are not its frames' poses (Open3D's test data has a trajectory.log
  // for a rendering demo), so no other name is guessed: give the file here.
  std::filesystem::path trajectory;
  // Empty: <dir>/camera_primesense.json, else the first *.json (by name) that has an
  // "intrinsic_matrix", else no intrinsics.
  std::filesystem::path intrinsics;
  // The files carry no stamps: frame i is stamped i / frame_rate_hz (the sensors record 30 Hz).
  double frame_rate_hz = 30.0;
};

// Frame i is the i-th line of rgbd.match when the folder has one, otherwise the i-th colour
// and the i-th depth image by name; its pose is the trajectory's entry i; depth_units_per_metre
// 1000. Problems, each skipping a frame or naming an unused pose: a colour or depth image
// without its partner, a file rgbd.match names that is not there, a frame without a pose, a
// pose without a frame, a trajectory or rgbd.match line that does not parse. Throws
// DatasetError naming the trajectory or intrinsics file when it is missing or unusable, and
// color/ or depth/ when missing without an rgbd.match; std::invalid_argument for a frame rate
// that is not positive.
RgbdSequence read_redwood(const std::filesystem::path& dir, const RedwoodOptions& options = {});

// parse_open3d_intrinsics on a file; DatasetError naming it when it cannot be read.
PinholeIntrinsics read_open3d_intrinsics(const std::filesystem::path& path);

}  // namespace semap::perception::datasets
