#include "semap/perception/geometry_segmenter.hpp"

#include <stdexcept>

#include "input_image.hpp"

namespace semap::perception {

GeometrySegmenter::GeometrySegmenter(int num_classes) : num_classes_(num_classes) {
  if (num_classes < 2) {
    throw std::invalid_argument("GeometrySegmenter: the map needs at least 2 classes, has " +
                                std::to_string(num_classes));
  }
}

Segmentation GeometrySegmenter::segment(const cv::Mat& bgr) {
  detail::require_bgr_image(bgr, "GeometrySegmenter::segment");
  Segmentation s;
  s.num_classes = num_classes_;
  s.labels = cv::Mat(bgr.size(), CV_16UC1, cv::Scalar(1));
  s.confidence = cv::Mat(bgr.size(), CV_32FC1, cv::Scalar(1.0f));
  return s;
}

}  // namespace semap::perception
