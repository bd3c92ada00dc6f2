#pragma once

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <string>

namespace semap::perception {

// Map class of a pixel the segmenter could not label (unknown palette colour, a model class
// configured to be dropped). Points with it never reach the map.
inline constexpr std::uint16_t kNoLabel = 0xFFFF;

// A segmented image, in map classes (class 0 is the map's free space; segmenters label hits
// with classes 1..K-1).
struct Segmentation {
  int num_classes = 0;    // K, the map's class count
  cv::Mat labels;         // CV_16UC1: argmax map class per pixel, or kNoLabel
  cv::Mat confidence;     // CV_32FC1: probability of that class, in [0, 1]
  cv::Mat probabilities;  // CV_32FC(K): per-pixel distribution over map classes; empty for
                          // segmenters that give hard labels only

  bool soft() const { return !probabilities.empty(); }
};

// One interface for every segmenter: a BGR image (CV_8UC3) in, a Segmentation of the same
// size out. A wrong input throws std::invalid_argument naming what is wrong.
class Segmenter {
 public:
  virtual ~Segmenter() = default;
  virtual Segmentation segment(const cv::Mat& bgr) = 0;
  virtual int num_classes() const = 0;
  virtual std::string describe() const = 0;  // for logs: kind, model file, input size
};

}  // namespace semap::perception
