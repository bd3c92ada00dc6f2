#include "semap/perception/datasets/redwood.hpp"

#include <algorithm>
#include <cctype>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include "semap/perception/datasets/redwood_files.hpp"
#include "text_fields.hpp"

namespace semap::perception::datasets {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// Regular files of `folder` whose extension is one of `extensions` (lower case), by name.
std::vector<fs::path> files_in(const fs::path& folder,
                               std::initializer_list<const char*> extensions) {
  if (!fs::is_directory(folder)) {
    throw DatasetError(folder.string() +
                       ": missing (a Redwood folder has color/ and depth/, or an rgbd.match)");
  }
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(folder)) {
    const std::string extension = lower(entry.path().extension().string());
    const bool wanted = std::any_of(extensions.begin(), extensions.end(),
                                    [&](const char* e) { return extension == e; });
    if (entry.is_regular_file() && wanted) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

// A colour and a depth image that belong together; `where` names the pairing.
struct ImagePair {
  std::string where;
  fs::path colour;
  fs::path depth;
};

std::vector<ImagePair> pairs_from_match(const fs::path& dir, const fs::path& match_path,
                                        std::vector<InputProblem>& problems) {
  const RgbdMatch match = parse_rgbd_match(read_text_file(match_path), match_path.string());
  problems.insert(problems.end(), match.problems.begin(), match.problems.end());
  std::vector<ImagePair> pairs;
  for (const RgbdMatchEntry& e : match.entries) {
    pairs.push_back({at_line(match_path.string(), e.line), dir / e.colour, dir / e.depth});
  }
  return pairs;
}

std::vector<ImagePair> pairs_by_name(const fs::path& dir, std::vector<InputProblem>& problems) {
  const std::vector<fs::path> colour = files_in(dir / "color", {".jpg", ".jpeg", ".png"});
  const std::vector<fs::path> depth = files_in(dir / "depth", {".png"});
  std::vector<ImagePair> pairs;
  const std::size_t n = std::min(colour.size(), depth.size());
  for (std::size_t i = 0; i < n; ++i) pairs.push_back({colour[i].string(), colour[i], depth[i]});
  const auto unpaired = [&](const std::vector<fs::path>& files, const char* other) {
    for (std::size_t i = n; i < files.size(); ++i) {
      problems.push_back({files[i].string(), "no " + std::string(other) + " image to pair with (" +
                                                 std::to_string(n) + " in " + other + "/)"});
    }
  };
  unpaired(colour, "depth");
  unpaired(depth, "color");
  return pairs;
}

fs::path trajectory_of(const fs::path& dir, const RedwoodOptions& options) {
  if (!options.trajectory.empty()) return options.trajectory;
  const fs::path odometry = dir / "odometry.log";
  if (!fs::is_regular_file(odometry)) {
    throw DatasetError(odometry.string() +
                       ": missing; name the frames' trajectory file (RedwoodOptions::trajectory)");
  }
  return odometry;
}

std::optional<fs::path> intrinsics_of(const fs::path& dir, const RedwoodOptions& options) {
  if (!options.intrinsics.empty()) return options.intrinsics;
  const fs::path primesense = dir / "camera_primesense.json";
  if (fs::is_regular_file(primesense)) return primesense;
  for (const fs::path& json : files_in(dir, {".json"})) {
    if (read_text_file(json).find("\"intrinsic_matrix\"") != std::string::npos) return json;
  }
  return std::nullopt;
}

}  // namespace

RgbdSequence read_redwood(const fs::path& dir, const RedwoodOptions& options) {
  if (!(options.frame_rate_hz > 0.0)) {
    throw std::invalid_argument("read_redwood: frame_rate_hz must be positive");
  }
  RgbdSequence sequence;
  sequence.depth_units_per_metre = 1000.0;
  auto& problems = sequence.problems;
  if (!fs::is_directory(dir)) throw DatasetError(dir.string() + ": not a directory");
  if (const auto intrinsics = intrinsics_of(dir, options)) {
    sequence.intrinsics = read_open3d_intrinsics(*intrinsics);
  }
  const fs::path trajectory = trajectory_of(dir, options);
  const RedwoodLog log = parse_redwood_log(read_text_file(trajectory), trajectory.string());
  problems.insert(problems.end(), log.problems.begin(), log.problems.end());

  const fs::path match = dir / "rgbd.match";
  const std::vector<ImagePair> pairs = fs::is_regular_file(match)
                                           ? pairs_from_match(dir, match, problems)
                                           : pairs_by_name(dir, problems);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const ImagePair& pair = pairs[i];
    if (i >= log.entries.size()) {
      problems.push_back({pair.where, "frame " + std::to_string(i) + " has no pose (" +
                                          trajectory.string() + " has " +
                                          std::to_string(log.entries.size()) + ")"});
      continue;
    }
    // An entry without a pose is already a problem of the trajectory's.
    if (!log.entries[i].world_from_camera) continue;
    std::string missing;
    for (const fs::path& file : {pair.colour, pair.depth}) {
      if (!fs::is_regular_file(file)) missing += (missing.empty() ? "" : ", ") + file.string();
    }
    if (!missing.empty()) {
      problems.push_back({pair.where, "no such file: " + missing});
      continue;
    }
    RgbdFrame frame;
    frame.stamp_s = static_cast<double>(i) / options.frame_rate_hz;
    frame.colour = pair.colour;
    frame.depth = pair.depth;
    frame.world_from_camera = *log.entries[i].world_from_camera;
    sequence.frames.push_back(std::move(frame));
  }
  for (std::size_t i = pairs.size(); i < log.entries.size(); ++i) {
    problems.push_back({at_line(trajectory.string(), log.entries[i].line),
                        "pose of frame " + std::to_string(i) + " has no colour and depth image (" +
                            std::to_string(pairs.size()) + " frames)"});
  }
  return sequence;
}

PinholeIntrinsics read_open3d_intrinsics(const fs::path& path) {
  return parse_open3d_intrinsics(read_text_file(path), path.string());
}

}  // namespace semap::perception::datasets
