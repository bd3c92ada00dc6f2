#pragma once

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "semap/common/messages.hpp"

namespace semap::map_io {

// A malformed PCD file; the message names the file and, where it applies, the line.
class PcdError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class PcdEncoding { kAscii, kBinary };

struct PcdScan {
  // Points, hard labels (field `label`) or soft labels (field `prob` with COUNT K), and the
  // sensor origin from VIEWPOINT.
  common::LabeledCloud cloud;
  // ASCII lines that carried more values than the header declares (read, then warned about).
  std::size_t lines_with_extra_values = 0;
};

// Reads PCD v0.7 with DATA ascii or binary. Fields x, y, z are required; `label` (integer or
// float) and `prob` (float, COUNT = number of classes) are optional; others are skipped.
// Without either label field every point gets label 0.
PcdScan read_pcd(const std::filesystem::path& path);
// Same, from bytes in memory; `name` is used in error messages.
PcdScan parse_pcd(std::string_view bytes, const std::string& name);

// Writes x y z label (hard labels) or x y z prob[K] (soft labels), VIEWPOINT = origin.
void write_pcd(const std::filesystem::path& path, const common::LabeledCloud& cloud,
               PcdEncoding encoding = PcdEncoding::kAscii);
std::string format_pcd(const common::LabeledCloud& cloud, PcdEncoding encoding);

}  // namespace semap::map_io
