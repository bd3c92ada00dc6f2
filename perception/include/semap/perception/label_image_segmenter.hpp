#pragma once

#include <string>

#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// Labels made beforehand, one image per frame (semap-segment's <stem>.labels.png, or a
// dataset's own annotation converted to map classes): each pixel's value is its map class id,
// 0 = no label. Read as a BGR image (grey replicated), the id is the first channel; every
// labelled pixel is certain. An id of num_classes or more throws std::invalid_argument naming
// the pixel and value.
class LabelImageSegmenter : public Segmenter {
 public:
  explicit LabelImageSegmenter(int num_classes);
  Segmentation segment(const cv::Mat& bgr) override;
  int num_classes() const override { return num_classes_; }
  std::string describe() const override { return "label images (map class ids)"; }

 private:
  int num_classes_;
};

}  // namespace semap::perception
