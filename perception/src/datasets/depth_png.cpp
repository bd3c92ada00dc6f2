#include "semap/perception/datasets/depth_png.hpp"

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>

#include "semap/perception/datasets/dataset.hpp"

namespace semap::perception::datasets {

namespace {

std::string describe_type(const cv::Mat& image) {
  const int depth = image.depth();
  const std::string bits = depth == CV_8U || depth == CV_8S     ? "8-bit"
                           : depth == CV_16U || depth == CV_16S ? "16-bit"
                                                                : "32/64-bit";
  return bits + " " + std::to_string(image.channels()) + "-channel";
}

}  // namespace

cv::Mat read_depth_metres(const std::filesystem::path& path, double units_per_metre) {
  if (!(units_per_metre > 0.0) || !std::isfinite(units_per_metre)) {
    throw std::invalid_argument("read_depth_metres: units per metre must be positive, got " +
                                std::to_string(units_per_metre));
  }
  if (!std::filesystem::is_regular_file(path)) throw DatasetError(path.string() + ": no such file");
  const cv::Mat raw = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
  if (raw.empty()) throw DatasetError(path.string() + ": cannot decode the image");
  if (raw.type() != CV_16UC1) {
    throw DatasetError(path.string() + ": depth image is " + describe_type(raw) +
                       ", expected 16-bit single-channel");
  }
  cv::Mat metres;
  // Raw 0 (no depth) stays 0.
  raw.convertTo(metres, CV_32FC1, 1.0 / units_per_metre);
  return metres;
}

}  // namespace semap::perception::datasets
