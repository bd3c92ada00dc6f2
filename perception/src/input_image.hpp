#pragma once

#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>

namespace semap::perception::detail {

// Segmenters take BGR CV_8UC3 images; anything else is a caller bug worth a clear message.
inline void require_bgr_image(const cv::Mat& image, const std::string& who) {
  if (image.empty()) throw std::invalid_argument(who + ": empty input image");
  if (image.type() != CV_8UC3) {
    throw std::invalid_argument(who + ": expected a BGR CV_8UC3 image, got " +
                                cv::typeToString(image.type()));
  }
}

// Probabilities are stored as a CV_32FC(K) image, and OpenCV caps channels at CV_CN_MAX.
inline void require_storable_class_count(int num_classes, const std::string& who) {
  if (num_classes < 2 || num_classes > CV_CN_MAX) {
    throw std::invalid_argument(who + ": the map needs 2.." + std::to_string(CV_CN_MAX) +
                                " classes, got " + std::to_string(num_classes));
  }
}

}  // namespace semap::perception::detail
