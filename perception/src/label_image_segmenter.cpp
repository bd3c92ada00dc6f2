#include "semap/perception/label_image_segmenter.hpp"

#include <stdexcept>

#include "input_image.hpp"

namespace semap::perception {

LabelImageSegmenter::LabelImageSegmenter(int num_classes) : num_classes_(num_classes) {
  if (num_classes < 2 || num_classes > 256) {
    throw std::invalid_argument(
        "LabelImageSegmenter: 8-bit label images hold 2..256 classes, not " +
        std::to_string(num_classes));
  }
}

Segmentation LabelImageSegmenter::segment(const cv::Mat& bgr) {
  detail::require_bgr_image(bgr, "LabelImageSegmenter::segment");
  Segmentation s;
  s.num_classes = num_classes_;
  s.labels = cv::Mat(bgr.size(), CV_16UC1);
  s.confidence = cv::Mat(bgr.size(), CV_32FC1, cv::Scalar(1.0f));
  for (int v = 0; v < bgr.rows; ++v) {
    const auto* in = bgr.ptr<cv::Vec3b>(v);
    auto* out = s.labels.ptr<std::uint16_t>(v);
    for (int u = 0; u < bgr.cols; ++u) {
      const int id = in[u][0];
      if (id >= num_classes_) {
        throw std::invalid_argument("label image: pixel (" + std::to_string(u) + ", " +
                                    std::to_string(v) + ") = " + std::to_string(id) +
                                    ", the map has classes 0.." + std::to_string(num_classes_ - 1));
      }
      out[u] = id == 0 ? kNoLabel : static_cast<std::uint16_t>(id);
    }
  }
  return s;
}

}  // namespace semap::perception
