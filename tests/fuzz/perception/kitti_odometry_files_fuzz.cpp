// A KITTI odometry sequence's files on any bytes; the first byte picks poses.txt, times.txt,
// calib.txt or a velodyne .bin. Rows that do not parse are problems named "name:line" and
// leave their row empty (row i stays line i + 1); poses are rigid; a calibration is usable or
// a CalibrationError; a scan has size / 16 points or is a DatasetError naming the file.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "dataset_fuzz_checks.hpp"
#include "semap/perception/datasets/kitti_odometry.hpp"
#include "semap/perception/datasets/kitti_odometry_files.hpp"
#include "semap/perception/datasets/velodyne_bin.hpp"

namespace pd = semap::perception::datasets;
using semap::fuzz::require;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (data[0] % 4) {
    case 0: {
      const pd::KittiPoses poses = pd::parse_kitti_poses(text, "poses.txt");
      semap::fuzz::require_named(poses.problems, "poses.txt");
      for (const auto& row : poses.rows) {
        if (row) semap::fuzz::require_rigid(*row);
      }
      break;
    }
    case 1: {
      const pd::KittiTimes times = pd::parse_kitti_times(text, "times.txt");
      semap::fuzz::require_named(times.problems, "times.txt");
      for (const auto& row : times.rows) require(!row || std::isfinite(*row));
      break;
    }
    case 2:
      try {
        const auto calib =
            pd::KittiOdometryCalib::from_text(semap::perception::KittiCalibText(text, "calib.txt"));
        semap::fuzz::require_rigid(calib.rect_from_velo());
        require(calib.p2.allFinite());
      } catch (const semap::perception::CalibrationError&) {
      }
      break;
    default:
      try {
        const auto bytes = std::as_bytes(std::span(data + 1, size - 1));
        require(pd::parse_velodyne_bin(bytes, "000000.bin").size() == (size - 1) / 16);
      } catch (const pd::DatasetError&) {
        require((size - 1) % 16 != 0);
      }
  }
  return 0;
}
