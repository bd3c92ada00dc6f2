#pragma once

// Camera intrinsics as a one-line text file, for datasets that do not ship them (TUM RGB-D
// documents them on its web site; ICL-NUIM in its paper):
//
//   # fx fy cx cy [width height]
//   535.4 539.2 320.1 247.6 640 480
//
// '#' comments and blank lines are allowed around the one line of numbers. A negative focal
// length is taken as given (ICL-NUIM's fy = -480 flips the image rows). Without a size, width
// and height are 0: the caller takes them from the images.
#include <filesystem>
#include <string>
#include <string_view>

#include "semap/perception/depth_projection.hpp"

namespace semap::perception::datasets {

// Throws DatasetError naming the file (and line) when it cannot be read, has no line or more
// than one line of numbers, a value that is not a number, a focal length of 0 or a size that
// is not a positive whole number of pixels.
PinholeIntrinsics read_intrinsics_text(const std::filesystem::path& path);
PinholeIntrinsics parse_intrinsics_text(std::string_view text, const std::string& name);

}  // namespace semap::perception::datasets
