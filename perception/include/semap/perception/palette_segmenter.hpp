#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <opencv2/core/matx.hpp>
#include <string>
#include <utility>
#include <vector>

#include "semap/perception/segmentation.hpp"

namespace semap::perception {

// A colour that stands for a class in a colour-coded label image.
struct PaletteEntry {
  std::string name;
  cv::Vec3b color;          // r, g, b
  std::uint16_t map_class;  // the map class it feeds, 1..K-1, or kNoLabel to drop it
};

// Map class per Cityscapes train id (0 road .. 18 bicycle).
using CityscapesMapping = std::array<std::uint16_t, 19>;

// Feeds a K = 4 map with the classes of the simulated world (SceneLabels): 1 ground (road,
// sidewalk, terrain), 2 building (building, wall, fence, vegetation), 3 pole (pole, traffic
// light, traffic sign). Sky and everything that moves are dropped.
CityscapesMapping cityscapes_default_mapping();

// The 19 Cityscapes train-id classes with their official names and colours; train id i
// feeds map_classes[i].
std::vector<PaletteEntry> cityscapes_palette(
    const CityscapesMapping& map_classes = cityscapes_default_mapping());

// Reads a palette from YAML as parallel lists, one entry per class:
//   names: [road, car]
//   colors: [128, 64, 128,  0, 0, 142]     # r, g, b
//   map_classes: [1, drop]                 # 1..num_classes-1, or drop
// Throws common::ConfigError naming the file, line and key (counts that do not agree, a bad
// colour or map class, a colour listed twice, unknown keys).
std::vector<PaletteEntry> load_palette_file(const std::filesystem::path& yaml, int num_classes);

struct PaletteOptions {
  // c in [1 / (K - 1), 1], so the labelled class stays the most likely one.
  float confidence = 0.9f;
  // false: hard labels only (Segmentation::probabilities stays empty).
  bool soft = true;
};

// Segments images whose colours encode classes (rendered label images, datasets' colour
// ground truth) by exact colour lookup. A colour not in the palette, or one that is dropped,
// gives kNoLabel with confidence 0.
//
// Soft label of a known colour with map class l, K map classes and confidence c:
//   p_l = c,   p_j = (1 - c) / (K - 2) for the other hit classes j in 1..K-1,   p_0 = 0,
// and the confidence image holds c (hard labels too).
class PaletteSegmenter : public Segmenter {
 public:
  // Throws std::invalid_argument for a map class outside 1..K-1, a colour listed twice or a
  // confidence outside [1 / (K - 1), 1].
  PaletteSegmenter(std::vector<PaletteEntry> palette, int num_classes, PaletteOptions options = {});

  Segmentation segment(const cv::Mat& bgr) override;
  int num_classes() const override { return num_classes_; }
  std::string describe() const override;

 private:
  std::uint16_t lookup(std::uint32_t rgb) const;

  std::vector<std::pair<std::uint32_t, std::uint16_t>> table_;  // 0xRRGGBB -> map class, sorted
  int num_classes_;
  PaletteOptions options_;
};

}  // namespace semap::perception
