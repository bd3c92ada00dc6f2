#include "semap/perception/datasets/tum.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <variant>

#include "semap/perception/datasets/stamp_association.hpp"
#include "semap/perception/datasets/tum_files.hpp"
#include "text_fields.hpp"

namespace semap::perception::datasets {

namespace fs = std::filesystem;

namespace {

std::string seconds(double s) {
  char text[40];
  std::snprintf(text, sizeof(text), "%.6f s", s);
  return text;
}

fs::path required_file(const fs::path& dir, const char* name) {
  const fs::path path = dir / name;
  if (!fs::is_regular_file(path)) {
    throw DatasetError(path.string() +
                       ": missing (a TUM RGB-D sequence has rgb.txt, depth.txt, groundtruth.txt)");
  }
  return path;
}

// The ground-truth pose at `stamp`, or why there is none.
std::variant<Eigen::Isometry3d, std::string> pose_at(const std::vector<TumPose>& poses,
                                                     double stamp, double max_gap_s) {
  const auto after =
      std::lower_bound(poses.begin(), poses.end(), stamp,
                       [](const TumPose& pose, double t) { return pose.stamp_s < t; });
  if (after != poses.end() && after->stamp_s == stamp) return after->world_from_camera;
  if (after == poses.begin() || after == poses.end()) {
    if (poses.empty()) return std::string("the ground truth has no pose");
    return "stamp " + seconds(stamp) + " is outside the ground truth (" +
           seconds(poses.front().stamp_s) + " to " + seconds(poses.back().stamp_s) + ")";
  }
  const TumPose& before = *(after - 1);
  const double gap = after->stamp_s - before.stamp_s;
  if (gap > max_gap_s) {
    return "the ground truth has a gap of " + seconds(gap) + " around stamp " + seconds(stamp);
  }
  const double f = (stamp - before.stamp_s) / gap;
  const Eigen::Quaterniond q0(before.world_from_camera.linear());
  const Eigen::Quaterniond q1(after->world_from_camera.linear());
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = q0.slerp(f, q1).toRotationMatrix();
  pose.translation() = (1.0 - f) * before.world_from_camera.translation() +
                       f * after->world_from_camera.translation();
  return pose;
}

std::vector<double> stamps_of(const TumList& list) {
  std::vector<double> stamps;
  stamps.reserve(list.entries.size());
  for (const TumListEntry& e : list.entries) stamps.push_back(e.stamp_s);
  return stamps;
}

}  // namespace

RgbdSequence read_tum(const fs::path& dir, const TumOptions& options) {
  if (!(options.max_difference_s > 0.0) || !(options.max_pose_gap_s > 0.0)) {
    throw std::invalid_argument("read_tum: max_difference_s and max_pose_gap_s must be positive");
  }
  const fs::path rgb_path = required_file(dir, "rgb.txt");
  const fs::path depth_path = required_file(dir, "depth.txt");
  const fs::path truth_path = required_file(dir, "groundtruth.txt");
  const TumList colour = parse_tum_list(read_text_file(rgb_path), rgb_path.string());
  const TumList depth = parse_tum_list(read_text_file(depth_path), depth_path.string());
  const TumGroundTruth truth =
      parse_tum_groundtruth(read_text_file(truth_path), truth_path.string());

  RgbdSequence sequence;
  sequence.depth_units_per_metre = 5000.0;
  auto& problems = sequence.problems;
  for (const auto* list : {&colour.problems, &depth.problems, &truth.problems}) {
    problems.insert(problems.end(), list->begin(), list->end());
  }

  const std::vector<double> colour_stamps = stamps_of(colour);
  const std::vector<double> depth_stamps = stamps_of(depth);
  std::vector<const TumListEntry*> partner(colour.entries.size(), nullptr);
  for (const StampPair& pair :
       associate_stamps(colour_stamps, depth_stamps, options.max_difference_s)) {
    partner[pair.first] = &depth.entries[pair.second];
  }

  for (std::size_t i = 0; i < colour.entries.size(); ++i) {
    const TumListEntry& entry = colour.entries[i];
    const std::string where = at_line(rgb_path.string(), entry.line);
    if (partner[i] == nullptr) {
      problems.push_back({where, "no depth frame within " + seconds(options.max_difference_s) +
                                     " of stamp " + seconds(entry.stamp_s)});
      continue;
    }
    const auto pose = pose_at(truth.poses, entry.stamp_s, options.max_pose_gap_s);
    if (const auto* why = std::get_if<std::string>(&pose)) {
      problems.push_back({where, *why});
      continue;
    }
    RgbdFrame frame;
    frame.stamp_s = entry.stamp_s;
    frame.colour = dir / entry.file;
    frame.depth = dir / partner[i]->file;
    frame.world_from_camera = std::get<Eigen::Isometry3d>(pose);
    if (!fs::is_regular_file(frame.colour)) {
      problems.push_back({where, frame.colour.string() + ": no such file"});
      continue;
    }
    if (!fs::is_regular_file(frame.depth)) {
      problems.push_back({at_line(depth_path.string(), partner[i]->line),
                          frame.depth.string() + ": no such file"});
      continue;
    }
    sequence.frames.push_back(std::move(frame));
  }
  std::stable_sort(sequence.frames.begin(), sequence.frames.end(),
                   [](const RgbdFrame& a, const RgbdFrame& b) { return a.stamp_s < b.stamp_s; });
  return sequence;
}

std::optional<PinholeIntrinsics> tum_intrinsics_for(const fs::path& dir) {
  struct Sensor {
    const char* tag;
    float fx, fy, cx, cy;
  };
  static constexpr Sensor kSensors[] = {{"freiburg1", 517.3f, 516.5f, 318.6f, 255.3f},
                                        {"freiburg2", 520.9f, 521.0f, 325.1f, 249.7f},
                                        {"freiburg3", 535.4f, 539.2f, 320.1f, 247.6f}};
  // The innermost folder that names a sensor: a sequence may sit in a folder of its own.
  const fs::path normal = dir.lexically_normal();
  for (auto part = normal.end(); part != normal.begin();) {
    const std::string name = (--part)->string();
    for (const Sensor& s : kSensors) {
      if (name.find(s.tag) != std::string::npos) {
        return PinholeIntrinsics{640, 480, s.fx, s.fy, s.cx, s.cy};
      }
    }
  }
  return std::nullopt;
}

}  // namespace semap::perception::datasets
