#pragma once

#include <cstdint>
#include <string>

#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// No labels, geometry only: every pixel is map class 1 ("occupied") with certainty, so the map
// learns occupancy alone. For a map of K = 2 classes (free, occupied), or any K where class 1
// stands for "something is there".
class GeometrySegmenter : public Segmenter {
 public:
  explicit GeometrySegmenter(int num_classes);
  Segmentation segment(const cv::Mat& bgr) override;
  int num_classes() const override { return num_classes_; }
  std::string describe() const override { return "no labels (geometry only)"; }

 private:
  int num_classes_;
};

}  // namespace semap::perception
