#pragma once

#include <cstdint>

namespace semap::perception {

// What turning one frame into labelled points dropped, by reason. Every step that drops a
// pixel or point counts it here; the onboard stage sums them into its health report.
struct DropCounts {
  std::uint64_t no_depth = 0;      // no return, invalid disparity, non-finite value
  std::uint64_t out_of_range = 0;  // beyond max_range
  // LiDAR point (or carried pixel) behind the camera or outside the (segmented) image
  std::uint64_t out_of_image = 0;
  std::uint64_t no_label = 0;        // the segmenter gave kNoLabel
  std::uint64_t low_confidence = 0;  // below min_confidence
  // Carried pixel whose depth the segmented frame saw differently (hidden from it, or moved)
  std::uint64_t occluded = 0;

  std::uint64_t total() const {
    return no_depth + out_of_range + out_of_image + no_label + low_confidence + occluded;
  }
  DropCounts& operator+=(const DropCounts& o) {
    no_depth += o.no_depth;
    out_of_range += o.out_of_range;
    out_of_image += o.out_of_image;
    no_label += o.no_label;
    low_confidence += o.low_confidence;
    occluded += o.occluded;
    return *this;
  }
};

// How labelled pixels become points, shared by the depth, stereo and LiDAR paths.
struct PointOptions {
  int stride = 1;               // use every stride-th pixel in u and v (depth and stereo)
  float max_range = 20.0f;      // metres from the sensor
  float min_confidence = 0.0f;  // pixels whose top class is less likely are dropped
  bool soft_labels = true;      // copy the segmenter's probabilities when it gives them
};

}  // namespace semap::perception
