#include "semap/perception/datasets/tum_files.hpp"

#include <algorithm>
#include <cmath>

#include "text_fields.hpp"

namespace semap::perception::datasets {

TumList parse_tum_list(std::string_view text, const std::string& name) {
  TumList list;
  for (const TextLine& line : text_lines(text)) {
    if (is_blank_or_comment(line.text)) continue;
    const std::vector<std::string_view> words = fields(line.text);
    TumListEntry entry;
    entry.line = line.number;
    if (words.size() != 2) {
      list.problems.push_back(
          {at_line(name, line.number),
           "expected 'timestamp filename', got " + std::to_string(words.size()) + " fields"});
    } else if (!parse_number(words[0], entry.stamp_s)) {
      list.problems.push_back(
          {at_line(name, line.number), "timestamp " + quoted(words[0]) + " is not a number"});
    } else {
      entry.file = std::string(words[1]);
      list.entries.push_back(std::move(entry));
    }
  }
  return list;
}

TumGroundTruth parse_tum_groundtruth(std::string_view text, const std::string& name) {
  // TUM writes four decimals per quaternion component, so the norm is 1 to about 1e-4.
  constexpr double kUnitTolerance = 1e-2;
  TumGroundTruth truth;
  for (const TextLine& line : text_lines(text)) {
    if (is_blank_or_comment(line.text)) continue;
    const auto problem = [&](const std::string& what) {
      truth.problems.push_back({at_line(name, line.number), what});
    };
    const std::vector<std::string_view> words = fields(line.text);
    if (words.size() != 8) {
      problem("expected 'timestamp tx ty tz qx qy qz qw', got " + std::to_string(words.size()) +
              " fields");
      continue;
    }
    double v[8];
    std::size_t bad = 0;
    while (bad < 8 && parse_number(words[bad], v[bad])) ++bad;
    if (bad < 8) {
      problem("value " + std::to_string(bad + 1) + " " + quoted(words[bad]) + " is not a number");
      continue;
    }
    // Eigen's constructor takes w first; the file has it last.
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (!(std::abs(q.norm() - 1.0) < kUnitTolerance)) {
      problem("quaternion norm " + std::to_string(q.norm()) + " is not 1");
      continue;
    }
    TumPose pose;
    pose.stamp_s = v[0];
    pose.world_from_camera.linear() = q.normalized().toRotationMatrix();
    pose.world_from_camera.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    truth.poses.push_back(pose);
  }
  std::stable_sort(truth.poses.begin(), truth.poses.end(),
                   [](const TumPose& a, const TumPose& b) { return a.stamp_s < b.stamp_s; });
  return truth;
}

}  // namespace semap::perception::datasets
