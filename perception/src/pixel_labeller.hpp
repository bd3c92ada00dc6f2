#pragma once

#include <Eigen/Core>
#include <opencv2/core/types.hpp>
#include <string>

#include "semap/common/messages.hpp"
#include "semap/perception/labelled_points.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// Gives body-frame points the class of the pixel they were seen in, shared by the depth, stereo
// and LiDAR paths so that every one labels, filters and counts the same way.
class PixelLabeller {
 public:
  // Checks the segmentation's layout once (throws std::invalid_argument naming the field) and
  // prepares `cloud` for hard or soft labels.
  PixelLabeller(const Segmentation& seg, const PointOptions& options, common::LabeledCloud& cloud);

  // Appends `p` with the label (or distribution) of pixel (u, v), which must lie inside the
  // image, or counts why not: kNoLabel or a top class below min_confidence.
  void add(const Eigen::Vector3f& p, int u, int v, DropCounts& drops);

 private:
  const Segmentation& seg_;
  float min_confidence_;
  bool soft_;
  common::LabeledCloud& cloud_;
};

// "what WxH": the one way size mismatches are reported.
std::string describe_size(const char* what, cv::Size size);

}  // namespace semap::perception
