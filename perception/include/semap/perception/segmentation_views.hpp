#pragma once

// What people look at for one segmentation: an 8-bit label image, a colour overlay on the
// camera image and the share of pixels per map class, named and coloured as the model card
// says. semap-segment writes and prints them.

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "semap/perception/model_card.hpp"
#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// How one map class is shown.
struct MapClassStyle {
  std::string name;
  cv::Vec3b color;  // r, g, b
};

// Per map class 0..K-1: the names of the model classes feeding it, joined by '+', and the
// colour of the first of them; "class N" in black for a class nothing feeds. Entry 0 is
// "no label": class 0 (free space) is never a pixel's label, so label images use 0 for
// pixels without one.
std::vector<MapClassStyle> map_class_styles(const ModelCard& card);

// CV_8UC1 map-class ids at the segmentation's size, kNoLabel as 0. Throws
// std::invalid_argument when the map has more than 256 classes (ids beyond 8 bits).
cv::Mat label_image(const Segmentation& segmentation);

// The BGR image with each labelled pixel blended half-way towards its class colour;
// unlabelled pixels stay as they are. `styles` as map_class_styles gives them.
cv::Mat class_overlay(const cv::Mat& bgr, const Segmentation& segmentation,
                      const std::vector<MapClassStyle>& styles);

// Fraction of the pixels per map class, K entries summing to 1; entry 0 holds the pixels
// without a label.
std::vector<double> class_shares(const Segmentation& segmentation);

}  // namespace semap::perception
