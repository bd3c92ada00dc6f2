#include "semap/perception/datasets/redwood_files.hpp"

#include <cmath>
#include <memory>

#include "rigid_pose.hpp"
#include "semap/common/config.hpp"
#include "text_fields.hpp"

namespace semap::perception::datasets {

namespace {

// One .log entry being read: its metadata line, then up to four matrix rows.
class LogEntryReader {
 public:
  LogEntryReader(const std::string& name, int frame, const TextLine& metadata)
      : name_(name), frame_(frame), entry_{metadata.number, std::nullopt} {
    const std::vector<std::string_view> words = fields(metadata.text);
    for (const std::string_view word : words) {
      double ignored = 0.0;
      if (!parse_number(word, ignored)) {
        note(metadata.number, "metadata " + quoted(word) + " is not a number");
      }
    }
  }

  bool complete() const { return rows_ == 4; }

  void add_row(const TextLine& line, const std::vector<std::string_view>& words) {
    for (int c = 0; c < 4; ++c) {
      if (!parse_number(words[static_cast<std::size_t>(c)], matrix_(rows_, c))) {
        note(line.number,
             "value " + quoted(words[static_cast<std::size_t>(c)]) + " is not a number");
      }
    }
    row_lines_[rows_++] = line.number;
  }

  // The entry, with its pose when every line parsed and the matrix is rigid.
  RedwoodLogEntry finish(std::vector<InputProblem>& problems) {
    if (!complete()) {
      note(entry_.line, "the 4x4 matrix has " + std::to_string(rows_) + " of 4 rows");
    } else if (!problem_) {
      if (!((matrix_.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() < 1e-6)) {
        note(row_lines_[3], "the last row is not 0 0 0 1");
      } else {
        entry_.world_from_camera =
            rigid_pose(matrix_.topLeftCorner<3, 3>(), matrix_.topRightCorner<3, 1>());
        if (!entry_.world_from_camera) {
          note(row_lines_[0], "the 3x3 block is not a rotation");
        }
      }
    }
    if (problem_) problems.push_back(std::move(*problem_));
    return entry_;
  }

 private:
  void note(int line, const std::string& what) {
    // The first problem of an entry is the one worth reading.
    if (!problem_) {
      problem_ =
          InputProblem{at_line(name_, line), "frame " + std::to_string(frame_) + ": " + what};
    }
  }

  const std::string& name_;
  int frame_;
  RedwoodLogEntry entry_;
  Eigen::Matrix4d matrix_ = Eigen::Matrix4d::Zero();
  int rows_ = 0;
  int row_lines_[4] = {};
  std::optional<InputProblem> problem_;
};

}  // namespace

RedwoodLog parse_redwood_log(std::string_view text, const std::string& name) {
  RedwoodLog log;
  // An entry still waiting for matrix rows. A pointer, not std::optional: GCC 12 at -O1 (the
  // sanitizer presets) warns that the optional's nested optional may be used uninitialised.
  std::unique_ptr<LogEntryReader> open;
  const auto close = [&] {
    if (open) log.entries.push_back(open->finish(log.problems));
    open.reset();
  };
  for (const TextLine& line : text_lines(text)) {
    if (is_blank_or_comment(line.text)) continue;
    const std::vector<std::string_view> words = fields(line.text);
    if (words.size() == 3) {
      close();
      open = std::make_unique<LogEntryReader>(name, static_cast<int>(log.entries.size()), line);
    } else if (words.size() == 4 && open) {
      open->add_row(line, words);
      if (open->complete()) close();
    } else {
      log.problems.push_back(
          {at_line(name, line.number), std::string(open ? "expected a matrix row of 4 numbers"
                                                        : "expected a metadata line 'i j k'") +
                                           ", got " + std::to_string(words.size()) + " fields"});
    }
  }
  close();
  return log;
}

RgbdMatch parse_rgbd_match(std::string_view text, const std::string& name) {
  RgbdMatch match;
  for (const TextLine& line : text_lines(text)) {
    if (is_blank_or_comment(line.text)) continue;
    const std::vector<std::string_view> words = fields(line.text);
    if (words.size() != 2) {
      match.problems.push_back(
          {at_line(name, line.number),
           "expected 'depth_file colour_file', got " + std::to_string(words.size()) + " fields"});
      continue;
    }
    match.entries.push_back({line.number, std::string(words[0]), std::string(words[1])});
  }
  return match;
}

PinholeIntrinsics parse_open3d_intrinsics(std::string_view json, const std::string& name) {
  try {
    // JSON is YAML's flow syntax: the YAML parser the project already links reads it, with
    // file:line in its messages.
    const auto root = common::ConfigSection::load_string(std::string(json), name);
    const auto side = [&](const char* key) {
      const double v = root.get<double>(key);
      if (!(v >= 1.0 && v <= 32768.0 && v == std::floor(v))) {
        root.reject(key, "must be whole pixels in [1, 32768]");
      }
      return static_cast<int>(v);
    };
    PinholeIntrinsics k;
    k.width = side("width");
    k.height = side("height");
    const std::vector<double> m = root.get<std::vector<double>>("intrinsic_matrix");
    if (m.size() != 9) {
      root.reject("intrinsic_matrix", "expected 9 numbers, got " + std::to_string(m.size()));
    }
    // Column-major: m[2], m[5], m[8] are the last row.
    if (m[2] != 0.0 || m[5] != 0.0 || m[8] != 1.0) {
      root.reject("intrinsic_matrix",
                  "the last row must be 0 0 1 (the matrix is stored column by column)");
    }
    if (m[1] != 0.0 || m[3] != 0.0) {
      root.reject("intrinsic_matrix", "expected fx 0 0 0 fy 0 cx cy 1 (no skew)");
    }
    k.fx = static_cast<float>(m[0]);
    k.fy = static_cast<float>(m[4]);
    k.cx = static_cast<float>(m[6]);
    k.cy = static_cast<float>(m[7]);
    if (!std::isfinite(k.fx) || !std::isfinite(k.fy) || !std::isfinite(k.cx) ||
        !std::isfinite(k.cy) || k.fx == 0.0f || k.fy == 0.0f) {
      root.reject("intrinsic_matrix", "focal lengths must be non-zero and values within float");
    }
    return k;
  } catch (const common::ConfigError& e) {
    throw DatasetError(e.what());
  }
}

}  // namespace semap::perception::datasets
