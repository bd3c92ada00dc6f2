#include "semap/perception/datasets/kitti_odometry.hpp"

#include <algorithm>
#include <charconv>
#include <string>

#include "rigid_pose.hpp"
#include "semap/perception/datasets/kitti_odometry_files.hpp"
#include "text_fields.hpp"

namespace semap::perception::datasets {

namespace fs = std::filesystem;

namespace {

fs::path required(const fs::path& path, const std::string& what) {
  if (!fs::is_regular_file(path)) throw DatasetError(path.string() + ": missing (" + what + ")");
  return path;
}

fs::path poses_path(const fs::path& sequence_dir, const fs::path& given) {
  if (!given.empty()) return required(given, "the poses file");
  const fs::path inside = sequence_dir / "poses.txt";
  if (fs::is_regular_file(inside)) return inside;
  // dataset/sequences/SS/ and dataset/poses/SS.txt; "SS/" names the folder SS.
  fs::path sequence = fs::absolute(sequence_dir).lexically_normal();
  if (!sequence.has_filename()) sequence = sequence.parent_path();
  const fs::path beside =
      sequence.parent_path().parent_path() / "poses" / (sequence.filename().string() + ".txt");
  if (fs::is_regular_file(beside)) return beside;
  throw DatasetError(inside.string() + " and " + beside.string() +
                     ": missing (the ground-truth poses of camera 0)");
}

// The scan number of velodyne/NNNNNN.bin.
std::optional<std::size_t> scan_index(const fs::path& scan) {
  const std::string stem = scan.stem().string();
  std::size_t index = 0;
  const auto [end, ec] = std::from_chars(stem.data(), stem.data() + stem.size(), index);
  if (stem.empty() || ec != std::errc() || end != stem.data() + stem.size()) return std::nullopt;
  return index;
}

}  // namespace

KittiOdometryCalib KittiOdometryCalib::from_text(const KittiCalibText& text) {
  const auto not_rigid = [&](const char* key) {
    return CalibrationError(text.name() + ": key '" + key + "': not a rigid transform");
  };
  KittiOdometryCalib calib;
  calib.p2 = text.matrix<3, 4>("P2");
  if (text.contains("R0_rect")) {
    const auto r0 = rigid_pose(text.matrix<3, 3>("R0_rect"), Eigen::Vector3d::Zero());
    if (!r0) throw not_rigid("R0_rect");
    calib.r0_rect = r0->linear();
  }
  // The odometry layout names the transform Tr, the object layout Tr_velo_to_cam.
  const char* key = text.contains("Tr") ? "Tr" : "Tr_velo_to_cam";
  if (!text.contains(key)) {
    throw CalibrationError(text.name() +
                           ": no key 'Tr' or 'Tr_velo_to_cam' (Velodyne to camera 0)");
  }
  const Eigen::Matrix<double, 3, 4> tr = text.matrix<3, 4>(key);
  const auto cam0_from_velo = rigid_pose(tr.leftCols<3>(), tr.col(3));
  if (!cam0_from_velo) throw not_rigid(key);
  calib.cam0_from_velo = *cam0_from_velo;
  return calib;
}

Eigen::Isometry3d KittiOdometryCalib::rect_from_velo() const {
  Eigen::Isometry3d rect = Eigen::Isometry3d::Identity();
  rect.linear() = r0_rect;
  return rect * cam0_from_velo;
}

KittiCameraCalibration KittiOdometryCalib::camera2(cv::Size image_size) const {
  KittiCameraCalibration camera;
  camera.image_size = image_size;
  camera.p_rect = p2;
  camera.r_rect = r0_rect;
  camera.cam_from_lidar = cam0_from_velo;
  return camera;
}

KittiOdometrySequence read_kitti_odometry(const fs::path& sequence_dir, const fs::path& poses_file,
                                          const KittiOdometryOptions& options) {
  const fs::path velodyne = sequence_dir / "velodyne";
  if (!fs::is_directory(velodyne)) throw DatasetError(velodyne.string() + ": not a directory");
  const fs::path times_path = required(sequence_dir / "times.txt", "the scans' stamps");
  const fs::path calib_path =
      required(options.calib.empty() ? sequence_dir / "calib.txt" : options.calib,
               "the calibration; KittiOdometryOptions::calib names another file");
  const fs::path pose_path = poses_path(sequence_dir, poses_file);

  KittiOdometrySequence sequence;
  try {
    sequence.calib = KittiOdometryCalib::from_text(KittiCalibText::read(calib_path));
  } catch (const CalibrationError& e) {
    throw DatasetError(e.what());
  }
  const KittiTimes times = parse_kitti_times(read_text_file(times_path), times_path.string());
  const KittiPoses poses = parse_kitti_poses(read_text_file(pose_path), pose_path.string());
  if (poses.rows.empty() || !poses.rows.front()) {
    const std::string why = poses.problems.empty() ? "no poses" : poses.problems.front().what;
    throw DatasetError(at_line(pose_path.string(), 1) +
                       ": the first pose defines the map frame: " + why);
  }
  auto& problems = sequence.problems;
  problems.insert(problems.end(), times.problems.begin(), times.problems.end());
  problems.insert(problems.end(), poses.problems.begin(), poses.problems.end());

  std::vector<fs::path> scans;
  for (const auto& entry : fs::directory_iterator(velodyne)) {
    if (entry.is_regular_file() && entry.path().extension() == ".bin")
      scans.push_back(entry.path());
  }
  std::sort(scans.begin(), scans.end());

  const Eigen::Isometry3d rect_from_velo = sequence.calib.rect_from_velo();
  const Eigen::Isometry3d velo_from_first =
      rect_from_velo.inverse() * poses.rows.front()->inverse();
  for (const fs::path& scan : scans) {
    const std::optional<std::size_t> index = scan_index(scan);
    if (!index) {
      problems.push_back({scan.string(), "the name is not a scan number (NNNNNN.bin)"});
      continue;
    }
    const auto missing_row = [&](const fs::path& file, std::size_t rows) {
      problems.push_back({scan.string(), "no row " + std::to_string(*index) + " in " +
                                             file.string() + " (" + std::to_string(rows) +
                                             " rows)"});
    };
    if (*index >= times.rows.size()) {
      missing_row(times_path, times.rows.size());
      continue;
    }
    if (*index >= poses.rows.size()) {
      missing_row(pose_path, poses.rows.size());
      continue;
    }
    // A row that did not parse is already a problem of its file's.
    if (!times.rows[*index] || !poses.rows[*index]) continue;
    LidarFrame frame;
    frame.stamp_s = *times.rows[*index];
    frame.scan = scan;
    const fs::path image = sequence_dir / "image_2" / (scan.stem().string() + ".png");
    if (fs::is_regular_file(image)) frame.image = image;
    frame.world_from_lidar = velo_from_first * *poses.rows[*index] * rect_from_velo;
    sequence.frames.push_back(std::move(frame));
  }
  return sequence;
}

}  // namespace semap::perception::datasets
