#pragma once

#include <cstdint>
#include <opencv2/core/mat.hpp>

#include "semap/perception/segmentation.hpp"

namespace semap::perception::fixtures {

// A distinct hit class (1..K-1) per pixel, so a point's label tells which pixel it came from.
inline std::uint16_t label_at(int u, int v, int num_classes) {
  return static_cast<std::uint16_t>(1 + (u + 3 * v) % (num_classes - 1));
}

// The probability the segmentation gives class c at pixel (u, v): 0.6 for the pixel's label,
// the rest spread by pixel and class so that every pixel's distribution differs. Sums to 1.
inline float probability_at(int u, int v, int c, int num_classes) {
  if (c == label_at(u, v, num_classes)) return 0.6f;
  float weight_sum = 0.0f;
  for (int j = 0; j < num_classes; ++j) {
    if (j != label_at(u, v, num_classes)) weight_sum += static_cast<float>(1 + (j + u) % 3);
  }
  return 0.4f * static_cast<float>(1 + (c + u) % 3) / weight_sum;
}

// labels = label_at, confidence 0.9, probabilities = probability_at when `soft`.
inline Segmentation make_segmentation(int width, int height, int num_classes, bool soft) {
  Segmentation seg;
  seg.num_classes = num_classes;
  seg.labels.create(height, width, CV_16UC1);
  seg.confidence.create(height, width, CV_32FC1);
  seg.confidence.setTo(0.9f);
  if (soft) seg.probabilities.create(height, width, CV_32FC(num_classes));
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      seg.labels.at<std::uint16_t>(v, u) = label_at(u, v, num_classes);
      if (!soft) continue;
      float* p = seg.probabilities.ptr<float>(v) + u * num_classes;
      for (int c = 0; c < num_classes; ++c) p[c] = probability_at(u, v, c, num_classes);
    }
  }
  return seg;
}

}  // namespace semap::perception::fixtures
