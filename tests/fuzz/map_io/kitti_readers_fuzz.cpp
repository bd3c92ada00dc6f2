// The SemanticKITTI readers on any bytes as a file: the first byte picks velodyne .bin
// (perception's read_velodyne_bin, which map_io's KittiSequence reads scans with), .label,
// poses.txt or calib.txt, the rest is the file (written to a per-process temporary). A reader
// returns what the bytes hold (.bin: size / 16 points equal to the bytes, .label: size / 4
// labels, poses and Tr: finite 3x4 matrices with the row 0 0 0 1) or throws KittiError (.bin:
// DatasetError) whose message starts with the file's path (and, for text files, names the line).
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "fuzz_input.hpp"
#include "semap/map_io/semantic_kitti_io.hpp"
#include "semap/perception/datasets/dataset.hpp"
#include "semap/perception/datasets/velodyne_bin.hpp"

namespace {

bool is_pose(const Eigen::Isometry3d& t) {
  return t.matrix().allFinite() && t.matrix().row(3) == Eigen::RowVector4d(0, 0, 0, 1);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace mi = semap::map_io;
  static const std::filesystem::path dir = [] {
    auto d =
        std::filesystem::temp_directory_path() / ("semap_kitti_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  semap::fuzz::FuzzInput in(data, size);
  const int kind = in.take<std::uint8_t>() % 4;
  const auto bytes = in.rest();
  const char* names[] = {"000000.bin", "000000.label", "poses.txt", "calib.txt"};
  const std::filesystem::path path = dir / names[kind];
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
    if (!out) std::abort();
  }
  try {
    switch (kind) {
      case 0: {
        const auto points = semap::perception::datasets::read_velodyne_bin(path);
        if (points.size() * 16 != bytes.size()) std::abort();
        for (std::size_t i = 0; i < points.size(); ++i) {
          if (std::memcmp(points[i].data(), bytes.data() + i * 16, 16) != 0) std::abort();
        }
        break;
      }
      case 1: {
        const auto labels = mi::read_kitti_labels(path);
        if (labels.size() * 4 != bytes.size()) std::abort();
        if (!labels.empty() && std::memcmp(labels.data(), bytes.data(), bytes.size()) != 0) {
          std::abort();
        }
        for (const auto label : labels) {
          if (mi::kitti_learning_map(label) >= mi::kKittiClasses) std::abort();
        }
        break;
      }
      case 2:
        for (const auto& pose : mi::read_kitti_poses(path)) {
          if (!is_pose(pose)) std::abort();
        }
        break;
      default:
        if (!is_pose(mi::read_kitti_velodyne_to_camera(path))) std::abort();
        break;
    }
  } catch (const mi::KittiError& e) {
    if (std::string(e.what()).rfind(path.string() + ":", 0) != 0) std::abort();
  } catch (const semap::perception::datasets::DatasetError& e) {
    if (kind != 0 || std::string(e.what()).rfind(path.string() + ":", 0) != 0) std::abort();
  }
  return 0;
}
