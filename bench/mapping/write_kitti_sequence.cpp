// Writes the synthetic 64-beam street of map_bench as a SemanticKITTI sequence, to time and
// score `semap-kitti semantic` on scans of SemanticKITTI's size (about 120k points, 20
// classes): velodyne/NNNNNN.bin (sensor frame), labels/NNNNNN.label (raw ids), poses.txt
// (camera poses) and calib.txt (Tr: the dataset's velodyne-to-camera axis swap).
//   write_kitti_sequence OUT_DIR [SCANS=300]
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "semap/map_io/semantic_kitti_io.hpp"
#include "synthetic_lidar.hpp"

namespace {

namespace fs = std::filesystem;

// Raw SemanticKITTI ids for the synthetic street's labels 0..19: road, sidewalk, then the
// parked vehicles (5..9), poles and signs (10, 11) and facades (12..19) as classes of the
// learning map, so that most of the 19 evaluated classes occur and a few stay absent.
constexpr std::array<std::uint32_t, 20> kRawIds{0,  40, 48, 0,  0,  10, 18, 20, 11, 15,
                                                80, 81, 50, 51, 70, 71, 72, 44, 49, 30};

void write_matrix(std::ofstream& out, const Eigen::Isometry3d& T) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) out << (r + c ? " " : "") << T(r, c);
  }
  out << '\n';
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: write_kitti_sequence OUT_DIR [SCANS]\n");
    return 1;
  }
  const fs::path out = argv[1];
  const int scans = argc > 2 ? std::stoi(argv[2]) : 300;
  fs::create_directories(out / "velodyne");
  fs::create_directories(out / "labels");
  // Tr takes velodyne (x forward, z up) to camera (z forward, y down) coordinates.
  Eigen::Isometry3d velo_to_cam = Eigen::Isometry3d::Identity();
  velo_to_cam.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  std::ofstream calib(out / "calib.txt");
  calib << "P0: 718.856 0 607.1928 0 0 718.856 185.2157 0 0 0 1 0\nTr: ";
  write_matrix(calib, velo_to_cam);
  std::ofstream poses(out / "poses.txt");
  poses.precision(9);
  const semap::bench::SyntheticLidar lidar;
  for (int s = 0; s < scans; ++s) {
    const semap::common::LabeledCloud cloud = lidar.scan(s);
    Eigen::Isometry3d world_velo = Eigen::Isometry3d::Identity();
    world_velo.translation() = cloud.origin.cast<double>();
    write_matrix(poses, world_velo * velo_to_cam.inverse());
    std::vector<float> xyzr;
    std::vector<std::uint32_t> raw;
    xyzr.reserve(cloud.size() * 4);
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Eigen::Vector3f p = cloud.points[i] - cloud.origin;
      xyzr.insert(xyzr.end(), {p.x(), p.y(), p.z(), 0.5f});
      raw.push_back(kRawIds.at(cloud.labels[i]));
    }
    const std::string name = semap::map_io::kitti_frame_name(static_cast<std::size_t>(s), "");
    std::ofstream(out / "velodyne" / (name + ".bin"), std::ios::binary)
        .write(reinterpret_cast<const char*>(xyzr.data()),
               static_cast<std::streamsize>(xyzr.size() * sizeof(float)));
    std::ofstream(out / "labels" / (name + ".label"), std::ios::binary)
        .write(reinterpret_cast<const char*>(raw.data()),
               static_cast<std::streamsize>(raw.size() * sizeof(std::uint32_t)));
  }
  std::printf("wrote %d scans to %s\n", scans, out.c_str());
  return 0;
}
