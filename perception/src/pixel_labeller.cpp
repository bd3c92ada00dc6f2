#include "pixel_labeller.hpp"

#include <stdexcept>

namespace semap::perception {

namespace {

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument("segmentation: " + message);
}

}  // namespace

std::string describe_size(const char* what, cv::Size size) {
  return std::string(what) + " " + std::to_string(size.width) + "x" + std::to_string(size.height);
}

PixelLabeller::PixelLabeller(const Segmentation& seg, const PointOptions& options,
                             common::LabeledCloud& cloud)
    : seg_(seg),
      min_confidence_(options.min_confidence),
      soft_(options.soft_labels && seg.soft()),
      cloud_(cloud) {
  // Class 0 is free space, so a map that can hold a hit has at least two classes.
  require(seg.num_classes >= 2 && seg.num_classes < kNoLabel,
          "num_classes " + std::to_string(seg.num_classes) + " outside [2, 65534]");
  require(seg.labels.type() == CV_16UC1 && !seg.labels.empty(), "labels must be CV_16UC1");
  require(seg.confidence.type() == CV_32FC1 && seg.confidence.size() == seg.labels.size(),
          "confidence must be CV_32FC1 of the labels' size (" +
              describe_size("labels", seg.labels.size()) + ", " +
              describe_size("confidence", seg.confidence.size()) + ")");
  if (soft_) {
    require(seg.probabilities.type() == CV_32FC(seg.num_classes) &&
                seg.probabilities.size() == seg.labels.size(),
            "probabilities must be CV_32FC(num_classes = " + std::to_string(seg.num_classes) +
                ") of the labels' size");
  }
  cloud_.num_classes = static_cast<std::uint16_t>(seg.num_classes);
}

void PixelLabeller::add(const Eigen::Vector3f& p, int u, int v, DropCounts& drops) {
  const std::uint16_t label = seg_.labels.at<std::uint16_t>(v, u);
  if (label == kNoLabel) {
    ++drops.no_label;
    return;
  }
  // A segmenter that labels a hit as free space (0) or beyond K would corrupt the map.
  if (label == 0 || label >= seg_.num_classes) {
    throw std::invalid_argument("segmentation: labels(" + std::to_string(u) + ", " +
                                std::to_string(v) + ") = " + std::to_string(label) +
                                ", hits carry classes 1.." + std::to_string(seg_.num_classes - 1));
  }
  if (seg_.confidence.at<float>(v, u) < min_confidence_) {
    ++drops.low_confidence;
    return;
  }
  cloud_.points.push_back(p);
  if (soft_) {
    const float* dist =
        seg_.probabilities.ptr<float>(v) + static_cast<std::ptrdiff_t>(u) * seg_.num_classes;
    cloud_.probabilities.insert(cloud_.probabilities.end(), dist, dist + seg_.num_classes);
  } else {
    cloud_.labels.push_back(label);
  }
}

}  // namespace semap::perception
