#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/mapping/map_params.hpp"

namespace semap::mapping {

// Training points of one scan: downsampled hits followed by downsampled free-space samples.
// A point with labels[i] >= 0 is one-hot in that class; labels[i] == kSoft uses the row i of
// `probabilities` (K floats), which exists for the first probabilities.size() / K points.
struct TrainingSet {
  static constexpr std::int32_t kSoft = -1;

  int num_classes = 0;
  std::vector<Eigen::Vector3f> points;
  std::vector<std::int32_t> labels;
  std::vector<float> probabilities;
  std::size_t num_hits = 0;
  // Input points dropped: non-finite, out of the grid range, or with a label >= K.
  std::size_t rejected = 0;
  // Input points beyond max_range.
  std::size_t out_of_range = 0;

  std::size_t size() const { return points.size(); }
};

// Builds the training set of a scan as the S-BKI paper does: hits within max_range are
// averaged per ds_res voxel (centroid; majority label, or mean probability vector); each
// downsampled hit casts a beam from `origin` with free samples every free_res metres up to
// one free_res short of the hit; those and the origin itself, labelled class 0, are averaged
// per ds_res voxel too. Throws std::invalid_argument when the cloud's label arrays do not
// match its points or its class count differs from params.num_classes.
TrainingSet build_training_set(const common::LabeledCloud& cloud, const Eigen::Vector3f& origin,
                               const MapParams& params);

}  // namespace semap::mapping
