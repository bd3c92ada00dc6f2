#include "semap/perception/geometry_segmenter.hpp"

#include <stdexcept>

namespace semap::perception {

GeometrySegmenter::GeometrySegmenter(int num_classes) : num_classes_(num_classes) {
  if (num_classes < 2) {
    throw std::invalid_argument("GeometrySegmenter: the map needs at least 2 classes, has " +
                                std::to_string(num_classes));
  }
}

Segmentation GeometrySegmenter::segment(const cv::Mat& bgr) {
  if (bgr.empty() || bgr.type() != CV_8UC3) {
    throw std::invalid_argument("GeometrySegmenter: expects a non-empty CV_8UC3 image");
  }
  Segmentation s;
  s.num_classes = num_classes_;
  s.labels = cv::Mat(bgr.size(), CV_16UC1, cv::Scalar(1));
  s.confidence = cv::Mat(bgr.size(), CV_32FC1, cv::Scalar(1.0f));
  return s;
}

}  // namespace semap::perception
