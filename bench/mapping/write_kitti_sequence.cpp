// Writes the synthetic 64-beam street of map_bench as a SemanticKITTI sequence, to time and
// score `semap-dataset semantickitti` on scans of SemanticKITTI's size (about 120k points, 20
// classes): velodyne/NNNNNN.bin (sensor frame), labels/NNNNNN.label (raw ids), poses.txt
// (camera poses) and calib.txt (Tr: the dataset's velodyne-to-camera axis swap).
//   write_kitti_sequence OUT_DIR [SCANS=300]
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
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
  semap::map_io::write_kitti_calibration(out / "calib.txt", velo_to_cam);
  std::vector<Eigen::Isometry3d> poses;
  const semap::bench::SyntheticLidar lidar;
  for (int s = 0; s < scans; ++s) {
    const semap::common::LabeledCloud cloud = lidar.scan(s);
    poses.push_back(Eigen::Translation3d(cloud.origin.cast<double>()) * velo_to_cam.inverse());
    std::vector<Eigen::Vector4f> xyzr;
    std::vector<std::uint32_t> raw;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Eigen::Vector3f p = cloud.points[i] - cloud.origin;
      xyzr.emplace_back(p.x(), p.y(), p.z(), 0.5f);
      raw.push_back(kRawIds.at(cloud.labels[i]));
    }
    const auto index = static_cast<std::size_t>(s);
    semap::map_io::write_kitti_scan(
        out / "velodyne" / semap::map_io::kitti_frame_name(index, ".bin"), xyzr);
    semap::map_io::write_kitti_labels(
        out / "labels" / semap::map_io::kitti_frame_name(index, ".label"), raw);
  }
  semap::map_io::write_kitti_poses(out / "poses.txt", poses);
  std::printf("wrote %d scans to %s\n", scans, out.c_str());
  return 0;
}
