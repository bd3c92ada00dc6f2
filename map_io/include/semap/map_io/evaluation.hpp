#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/mapping/confusion_matrix.hpp"
#include "semap/mapping/semantic_map.hpp"

namespace semap::map_io {

// Queries `map` at every point of `scans` and compares with their labels (a point where the
// map knows nothing counts as no label, a miss).
mapping::ConfusionMatrix score_map(const mapping::SemanticMap& map,
                                   std::span<const common::LabeledCloud> scans);

// One row of the label-noise study: a map built from scans whose labels were flipped, scored
// at the scan points against the clean labels over the occupied classes 1..K-1.
struct NoiseResult {
  double noise = 0.0;
  mapping::MapMethod method = mapping::MapMethod::kBki;
  mapping::ConfusionMatrix confusion{1};
  double mean_iou = 0.0;
};

// For every fraction in `noise` and both methods: flip that fraction of every scan's labels
// (seed + scan index), build the map with `params` (method replaced), score it. Rows come
// in the order noise-major, S-BKI before S-CSM.
std::vector<NoiseResult> evaluate_label_noise(std::span<const common::LabeledCloud> clean,
                                              const mapping::MapParams& params,
                                              std::span<const double> noise, std::uint64_t seed);

}  // namespace semap::map_io
