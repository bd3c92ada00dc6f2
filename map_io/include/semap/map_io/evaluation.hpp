#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/mapping/semantic_map.hpp"

namespace semap::map_io {

// Per-class confusion counts of predicted against true labels, as in the SemanticKITTI
// benchmark. A prediction of -1 (the map knows nothing there) counts as a miss of the true
// class; true labels outside [0, K) are ignored.
class ConfusionMatrix {
 public:
  explicit ConfusionMatrix(int num_classes);

  void add(int truth, int predicted);
  void merge(const ConfusionMatrix& other);

  int num_classes() const { return k_; }
  std::uint64_t count(int truth, int predicted) const;  // predicted may be -1
  std::uint64_t total() const { return total_; }
  // Points whose true class is c, whatever was predicted.
  std::uint64_t truth_count(int c) const;

  // TP / (TP + FP + FN); NaN when the class appears neither in truth nor in predictions.
  double iou(int c) const;
  // Mean of iou(c) over `classes`, skipping NaN entries.
  double mean_iou(std::span<const int> classes) const;

 private:
  int k_;
  std::vector<std::uint64_t> counts_;  // k_ rows, k_ + 1 columns (last: unknown)
  std::uint64_t total_ = 0;
};

// Queries `map` at every point of `scans` and compares with their labels.
ConfusionMatrix score_map(const mapping::SemanticMap& map,
                          std::span<const common::LabeledCloud> scans);

// One row of the label-noise study: a map built from scans whose labels were flipped, scored
// at the scan points against the clean labels over the occupied classes 1..K-1.
struct NoiseResult {
  double noise = 0.0;
  mapping::MapMethod method = mapping::MapMethod::kBki;
  ConfusionMatrix confusion{1};
  double mean_iou = 0.0;
};

// For every fraction in `noise` and both methods: flip that fraction of every scan's labels
// (seed + scan index), build the map with `params` (method replaced), score it. Rows come
// in the order noise-major, S-BKI before S-CSM.
std::vector<NoiseResult> evaluate_label_noise(std::span<const common::LabeledCloud> clean,
                                              const mapping::MapParams& params,
                                              std::span<const double> noise, std::uint64_t seed);

}  // namespace semap::map_io
