#include "semap/perception/stereo_depth.hpp"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <utility>

#include "pixel_labeller.hpp"

namespace semap::perception {

namespace {

void require(bool ok, const char* field, int value) {
  if (!ok) {
    throw std::invalid_argument(std::string("StereoOptions.") + field + ": " +
                                std::to_string(value) + " is out of range");
  }
}

// The rectified half: remapped when the calibration asks for it, shared otherwise.
cv::Mat rectify(const cv::Mat& half, const cv::Mat& map1, const cv::Mat& map2) {
  if (map1.empty()) return half;
  cv::Mat out;
  cv::remap(half, out, map1, map2, cv::INTER_LINEAR);
  return out;
}

cv::Mat grey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat out;
  cv::cvtColor(image, out, cv::COLOR_BGR2GRAY);
  return out;
}

}  // namespace

StereoDepth::StereoDepth(StereoCalibration calibration, const StereoOptions& options)
    : calibration_(std::move(calibration)) {
  require(options.num_disparities > 0 && options.num_disparities % 16 == 0, "num_disparities",
          options.num_disparities);
  require(options.block_size > 0 && options.block_size % 2 == 1, "block_size", options.block_size);
  require(options.uniqueness >= 0, "uniqueness", options.uniqueness);
  require(options.speckle_window >= 0, "speckle_window", options.speckle_window);
  require(options.speckle_range >= 0, "speckle_range", options.speckle_range);
  // OpenCV's recommended smoothness penalties for one channel: P1 = 8 b^2, P2 = 32 b^2.
  const int area = options.block_size * options.block_size;
  sgbm_ = cv::StereoSGBM::create(0, options.num_disparities, options.block_size, 8 * area,
                                 32 * area, 1, 63, options.uniqueness, options.speckle_window,
                                 options.speckle_range, cv::StereoSGBM::MODE_SGBM_3WAY);
}

StereoFrame StereoDepth::compute(const cv::Mat& frame) {
  const cv::Size half = calibration_.half_size;
  const cv::Size expected(2 * half.width, half.height);
  if (frame.size() != expected) {
    throw std::invalid_argument("StereoDepth: " + describe_size("frame", frame.size()) + ", " +
                                describe_size("calibration expects", expected) +
                                " (two halves side by side)");
  }
  if (frame.type() != CV_8UC3 && frame.type() != CV_8UC1) {
    throw std::invalid_argument("StereoDepth: frame must be CV_8UC3 (BGR) or CV_8UC1 (grey)");
  }
  const cv::Mat left = frame(cv::Rect(0, 0, half.width, half.height));
  const cv::Mat right = frame(cv::Rect(half.width, 0, half.width, half.height));

  StereoFrame out;
  out.intrinsics = calibration_.rectified;
  out.left_from_rectified = calibration_.left_from_rectified;
  const cv::Mat left_rect = rectify(left, calibration_.left_map1, calibration_.left_map2);
  const cv::Mat left_grey = grey(left_rect);
  if (left_rect.channels() == 3) {
    out.left_bgr = left_rect.clone();  // detach from the caller's frame
  } else {
    cv::cvtColor(left_rect, out.left_bgr, cv::COLOR_GRAY2BGR);
  }
  // Only the left half is shown to the segmenter: the right one is rectified in grey.
  const cv::Mat right_grey = rectify(grey(right), calibration_.right_map1, calibration_.right_map2);

  cv::Mat disparity16;  // CV_16S, 16 x disparity; SGBM marks failures negative
  sgbm_->compute(left_grey, right_grey, disparity16);

  // Depth of a rectified pair from disparity d = D16 / 16 pixels:
  //   Z = f B / d = 16 f B / D16                                                    (1)
  // d <= 0 (no match, or a point at infinity) has no depth.
  const float scaled = 16.0f * out.intrinsics.fx * calibration_.baseline_m;
  out.depth.create(half, CV_32FC1);
  for (int v = 0; v < half.height; ++v) {
    const auto* d16 = disparity16.ptr<std::int16_t>(v);
    auto* z = out.depth.ptr<float>(v);
    for (int u = 0; u < half.width; ++u) z[u] = d16[u] > 0 ? scaled / d16[u] : 0.0f;
  }
  return out;
}

}  // namespace semap::perception
