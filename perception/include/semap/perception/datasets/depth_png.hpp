#pragma once

#include <filesystem>
#include <opencv2/core/mat.hpp>

namespace semap::perception::datasets {

// A depth image in metres (CV_32FC1; 0 = no depth) from a 16-bit single-channel PNG whose raw
// value `units_per_metre` is one metre (TUM 5000, Redwood 1000). Throws DatasetError naming the
// file when it cannot be read or holds anything else (an 8-bit or colour image is a colour
// file given as depth, or a depth map saved lossily), std::invalid_argument when
// units_per_metre is not a positive number.
cv::Mat read_depth_metres(const std::filesystem::path& path, double units_per_metre);

}  // namespace semap::perception::datasets
