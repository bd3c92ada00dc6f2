#include "semap/map_io/semantic_kitti_io.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <unordered_map>

#include "semap/perception/datasets/dataset.hpp"
#include "semap/perception/datasets/velodyne_bin.hpp"

namespace semap::map_io {

namespace {

std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw KittiError(path.string() + ": cannot open");
  return {std::istreambuf_iterator<char>(in), {}};
}

// Parses exactly 12 numbers (a row-major 3x4 matrix) from `text`.
bool parse_3x4(std::istringstream& in, Eigen::Isometry3d& out) {
  Eigen::Matrix<double, 3, 4> m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (!(in >> m(r, c))) return false;
    }
  }
  std::string rest;
  if (in >> rest) return false;
  out = Eigen::Isometry3d::Identity();
  out.matrix().topRows<3>() = m;
  return true;
}

void write_bytes(const std::filesystem::path& path, const void* data, std::size_t bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  if (!out) throw KittiError(path.string() + ": cannot write");
}

// A row-major 3x4 matrix on one line, as poses.txt and calib.txt hold it.
void write_3x4(std::ofstream& out, const Eigen::Isometry3d& T) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) out << (r + c > 0 ? " " : "") << T(r, c);
  }
  out << '\n';
}

}  // namespace

std::string kitti_frame_name(std::size_t index, std::string_view extension) {
  char digits[24];
  std::snprintf(digits, sizeof(digits), "%06zu", index);
  return std::string(digits).append(extension);
}

std::uint16_t kitti_learning_map(std::uint32_t raw_label) {
  static const std::unordered_map<std::uint32_t, std::uint16_t> kMap{
      {0, 0},   {1, 0},   {10, 1},  {11, 2},  {13, 5},  {15, 3},  {16, 5},  {18, 4},  {20, 5},
      {30, 6},  {31, 7},  {32, 8},  {40, 9},  {44, 10}, {48, 11}, {49, 12}, {50, 13}, {51, 14},
      {52, 0},  {60, 9},  {70, 15}, {71, 16}, {72, 17}, {80, 18}, {81, 19}, {99, 0},  {252, 1},
      {253, 7}, {254, 6}, {255, 8}, {256, 5}, {257, 5}, {258, 4}, {259, 5}};
  const auto it = kMap.find(raw_label & 0xFFFFu);
  return it == kMap.end() ? 0 : it->second;
}

const std::array<const char*, kKittiClasses>& kitti_class_names() {
  static const std::array<const char*, kKittiClasses> kNames{
      "unlabeled", "car",          "bicycle", "motorcycle", "truck",    "other-vehicle", "person",
      "bicyclist", "motorcyclist", "road",    "parking",    "sidewalk", "other-ground",  "building",
      "fence",     "vegetation",   "trunk",   "terrain",    "pole",     "traffic-sign"};
  return kNames;
}

std::vector<std::uint32_t> read_kitti_labels(const std::filesystem::path& path) {
  const std::string bytes = read_bytes(path);
  if (bytes.size() % sizeof(std::uint32_t) != 0) {
    throw KittiError(path.string() + ": size " + std::to_string(bytes.size()) +
                     " is not a multiple of 4 bytes");
  }
  std::vector<std::uint32_t> labels(bytes.size() / sizeof(std::uint32_t));
  // An empty file gives no labels (memcpy must not see the empty vector's null pointer).
  if (!labels.empty()) std::memcpy(labels.data(), bytes.data(), bytes.size());
  return labels;
}

std::vector<Eigen::Isometry3d> read_kitti_poses(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw KittiError(path.string() + ": cannot open");
  std::vector<Eigen::Isometry3d> poses;
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream fields(line);
    Eigen::Isometry3d pose;
    if (!parse_3x4(fields, pose)) {
      throw KittiError(path.string() + ":" + std::to_string(line_no) +
                       ": expected 12 numbers (3x4 pose)");
    }
    poses.push_back(pose);
  }
  return poses;
}

Eigen::Isometry3d read_kitti_velodyne_to_camera(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw KittiError(path.string() + ": cannot open");
  std::string line;
  std::size_t line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.rfind("Tr:", 0) != 0) continue;
    std::istringstream fields(line.substr(3));
    Eigen::Isometry3d tr;
    if (!parse_3x4(fields, tr)) {
      throw KittiError(path.string() + ":" + std::to_string(line_no) +
                       ": Tr needs 12 numbers (3x4 matrix)");
    }
    return tr;
  }
  throw KittiError(path.string() + ": no Tr: line");
}

void write_kitti_scan(const std::filesystem::path& path, std::span<const Eigen::Vector4f> points) {
  std::vector<float> xyzr;
  xyzr.reserve(points.size() * 4);
  for (const Eigen::Vector4f& p : points) xyzr.insert(xyzr.end(), p.data(), p.data() + 4);
  write_bytes(path, xyzr.data(), xyzr.size() * sizeof(float));
}

void write_kitti_labels(const std::filesystem::path& path, std::span<const std::uint32_t> labels) {
  write_bytes(path, labels.data(), labels.size_bytes());
}

void write_kitti_poses(const std::filesystem::path& path,
                       std::span<const Eigen::Isometry3d> poses) {
  std::ofstream out(path);
  out.precision(17);
  for (const Eigen::Isometry3d& pose : poses) write_3x4(out, pose);
  if (!out) throw KittiError(path.string() + ": cannot write");
}

void write_kitti_calibration(const std::filesystem::path& path,
                             const Eigen::Isometry3d& velo_to_cam) {
  std::ofstream out(path);
  out.precision(17);
  out << "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nTr: ";
  write_3x4(out, velo_to_cam);
  if (!out) throw KittiError(path.string() + ": cannot write");
}

KittiSequence::KittiSequence(std::filesystem::path folder)
    : folder_(std::move(folder)),
      poses_(read_kitti_poses(folder_ / "poses.txt")),
      velo_to_cam_(read_kitti_velodyne_to_camera(folder_ / "calib.txt")) {}

Eigen::Isometry3d KittiSequence::lidar_pose(std::size_t index) const {
  // poses.txt holds camera poses; the LiDAR pose follows through the calibration.
  return poses_.at(index) * velo_to_cam_;
}

common::LabeledCloud KittiSequence::scan(std::size_t index) const {
  if (index >= poses_.size()) {
    throw KittiError(folder_.string() + ": scan " + std::to_string(index) + " beyond " +
                     std::to_string(poses_.size()) + " poses");
  }
  const auto scan_path = folder_ / "velodyne" / kitti_frame_name(index, ".bin");
  const auto label_path = folder_ / "labels" / kitti_frame_name(index, ".label");
  std::vector<Eigen::Vector4f> points;
  try {
    points = perception::datasets::read_velodyne_bin(scan_path);
  } catch (const perception::datasets::DatasetError& e) {
    throw KittiError(e.what());  // names the file
  }
  const auto labels = read_kitti_labels(label_path);
  if (labels.size() != points.size()) {
    throw KittiError(label_path.string() + ": " + std::to_string(labels.size()) + " labels for " +
                     std::to_string(points.size()) + " points in " + scan_path.string());
  }
  const Eigen::Isometry3f pose = lidar_pose(index).cast<float>();
  common::LabeledCloud cloud;
  cloud.num_classes = kKittiClasses;
  cloud.origin = pose.translation();
  cloud.points.reserve(points.size());
  cloud.labels.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    cloud.points.push_back(pose * points[i].head<3>());
    cloud.labels.push_back(kitti_learning_map(labels[i]));
  }
  return cloud;
}

}  // namespace semap::map_io
