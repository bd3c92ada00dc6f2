#pragma once

// TUM RGB-D sequences (https://cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats): a
// folder with rgb.txt, depth.txt and groundtruth.txt, the images it names, depth in 1/5000 m.
#include <filesystem>
#include <optional>

#include "semap/perception/datasets/rgbd_sequence.hpp"
#include "semap/perception/depth_projection.hpp"

namespace semap::perception::datasets {

struct TumOptions {
  // Colour and depth frames pair when their stamps differ by less than this (associate.py's
  // default; the Kinect streams both at 30 Hz, 33 ms apart).
  double max_difference_s = 0.02;
  // A frame's pose is interpolated between the ground-truth samples around its stamp (100 Hz
  // motion capture); samples farther apart than this mean the capture lost the camera there.
  double max_pose_gap_s = 0.1;
};

// Every colour frame with a depth frame (associate_stamps), its pose interpolated at the colour
// stamp (translation linear, rotation slerp) and both files present; depth_units_per_metre
// 5000; no intrinsics (the files carry none: tum_intrinsics_for or read_intrinsics_text).
// Problems, each skipping one frame: a line of any of the three files that does not parse, a
// colour frame without a depth frame within max_difference_s, a stamp outside the ground
// truth or in one of its gaps, a named image that is not there. Depth frames left without a
// colour frame are not frames of the sequence and are not reported. Throws DatasetError naming
// a missing or unreadable rgb.txt, depth.txt or groundtruth.txt, std::invalid_argument for
// options that are not positive.
RgbdSequence read_tum(const std::filesystem::path& dir, const TumOptions& options = {});

// The colour camera's intrinsics that TUM publishes for its three sensors (640x480), chosen by
// "freiburg1", "freiburg2" or "freiburg3" in the folder's name (rgbd_dataset_freiburg1_xyz):
// fr1 517.3 516.5 318.6 255.3, fr2 520.9 521.0 325.1 249.7, fr3 535.4 539.2 320.1 247.6. The
// lens distortion TUM gives for fr1 and fr2 is not modelled. Nothing for another name.
std::optional<PinholeIntrinsics> tum_intrinsics_for(const std::filesystem::path& dir);

}  // namespace semap::perception::datasets
