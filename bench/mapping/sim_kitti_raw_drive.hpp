#pragma once

// A simulated drive written in the KITTI raw layout, for semap-dataset kitti-raw's tests and
// figures: the estimation simulator's car drives through the perception simulator's street,
// and the drive is stored as an OXTS unit, a Velodyne and a labelled left colour camera would
// store it.
#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "semap/sim/drive_simulator.hpp"
#include "semap/sim/world.hpp"

namespace semap::bench {

struct SimKittiRawOptions {
  double duration_s = 32.0;  // of the simulator (2 s at rest first); 10 packets and scans per s
  int beams = 64;            // elevations from -24.8 to +2 degrees, as the HDL-64
  int azimuths = 1000;       // per revolution
  float max_range = 80.0f;
  int label_stride = 4;  // the label image is cast every so many pixels (and upscaled)
  // Also render image_02/data/*.png (the simulated colour camera, for --segmenter runs); about
  // 0.1 s per frame at KITTI's 1242 x 375.
  bool colour_images = false;
  // Height of the IMU above the ground (KITTI's OXTS unit sits about 0.93 m up).
  double imu_height_m = 0.93;
  std::uint64_t seed = 1;
};

// What the writer produced, for checks against the truth.
struct SimKittiRawDrive {
  std::filesystem::path calib_dir;    // <root>/2011_09_26 with the three calibration files
  std::filesystem::path drive_dir;    // <calib_dir>/2011_09_26_drive_0001_sync
  std::filesystem::path labels_dir;   // <drive_dir>/labels_02: 8-bit map class ids per scan
  std::filesystem::path image_dir;    // <drive_dir>/image_02/data (with colour_images)
  estimation::DriveData simulation;   // the 100 Hz truth and IMU the packets came from
  std::vector<Eigen::Vector3d> path;  // world path of the street (ENU, metres)
  std::size_t scans = 0;
};

// Writes the drive under `root`, with the KITTI calibration files found in `kitti_calib`
// (calib_cam_to_cam.txt, calib_velo_to_cam.txt, calib_imu_to_velo.txt) copied next to it.
// OXTS packets at 10 Hz hold the truth and the mean of the ten 100 Hz IMU samples before them;
// scans are stamped half-way between packets and cast from the true pose at that stamp.
// Classes are those of perception::kSimMapClassTable (8).
SimKittiRawDrive write_sim_kitti_raw_drive(const std::filesystem::path& root,
                                           const std::filesystem::path& kitti_calib,
                                           const SimKittiRawOptions& options = {});

// The street of a written drive (the same world the scans were cast in), z = 0 on the ground;
// a map point p (ENU of the first packet) lies at p + (0, 0, imu_height_m) in it.
sim::SimWorld sim_kitti_raw_world(const SimKittiRawDrive& drive,
                                  const SimKittiRawOptions& options = {});

}  // namespace semap::bench
