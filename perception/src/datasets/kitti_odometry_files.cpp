#include "semap/perception/datasets/kitti_odometry_files.hpp"

#include "rigid_pose.hpp"
#include "text_fields.hpp"

namespace semap::perception::datasets {

KittiPoses parse_kitti_poses(std::string_view text, const std::string& name) {
  KittiPoses poses;
  for (const TextLine& line : text_lines(text)) {
    std::optional<Eigen::Isometry3d>& row = poses.rows.emplace_back();
    const auto problem = [&](const std::string& what) {
      poses.problems.push_back({at_line(name, line.number), what});
    };
    const std::vector<std::string_view> words = fields(line.text);
    if (words.size() != 12) {
      problem("expected 12 numbers (row-major 3x4 pose), got " + std::to_string(words.size()) +
              " fields");
      continue;
    }
    Eigen::Matrix<double, 3, 4> m;
    std::size_t bad = 0;
    while (bad < 12 && parse_number(words[bad], m(static_cast<Eigen::Index>(bad / 4),
                                                  static_cast<Eigen::Index>(bad % 4)))) {
      ++bad;
    }
    if (bad < 12) {
      problem("value " + std::to_string(bad + 1) + " " + quoted(words[bad]) + " is not a number");
      continue;
    }
    row = rigid_pose(m.leftCols<3>(), m.col(3));
    if (!row) problem("the 3x3 block is not a rotation");
  }
  return poses;
}

KittiTimes parse_kitti_times(std::string_view text, const std::string& name) {
  KittiTimes times;
  for (const TextLine& line : text_lines(text)) {
    std::optional<double>& row = times.rows.emplace_back();
    const std::vector<std::string_view> words = fields(line.text);
    double stamp = 0.0;
    if (words.size() != 1 || !parse_number(words[0], stamp)) {
      times.problems.push_back(
          {at_line(name, line.number), "expected one stamp in seconds, got " + quoted(line.text)});
      continue;
    }
    row = stamp;
  }
  return times;
}

}  // namespace semap::perception::datasets
