// write_kitti_raw_drive: a simulated drive in the KITTI raw layout (OXTS, Velodyne, label
// images, calibration), for running semap-dataset kitti-raw without the dataset (docs/kitti.md).
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "sim_kitti_raw_drive.hpp"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr,
                 "usage: write_kitti_raw_drive ROOT KITTI_CALIB_DIR [SECONDS [AZIMUTHS [colour]]]\n"
                 "  writes ROOT/2011_09_26/2011_09_26_drive_0001_sync (10 scans per second after "
                 "2 s at rest; labels in labels_02/; `colour`: also image_02/data/ from the "
                 "simulated camera)\n");
    return 2;
  }
  semap::bench::SimKittiRawOptions options;
  if (argc > 3) options.duration_s = std::atof(argv[3]);
  if (argc > 4) options.azimuths = std::atoi(argv[4]);
  options.colour_images = argc > 5 && std::string(argv[5]) == "colour";
  try {
    const auto drive = semap::bench::write_sim_kitti_raw_drive(argv[1], argv[2], options);
    std::printf("%s: %zu scans\n", drive.drive_dir.c_str(), drive.scans);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "write_kitti_raw_drive: %s\n", e.what());
    return 1;
  }
  return 0;
}
