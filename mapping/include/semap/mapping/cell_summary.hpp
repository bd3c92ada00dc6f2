#pragma once

#include <span>
#include <vector>

#include "semap/mapping/map_params.hpp"

namespace semap::mapping {

// What a user asks of one cell, whatever the map method.
struct CellSummary {
  bool known = false;
  bool occupied = false;
  int label = 0;             // most probable class
  float probability = 0.0f;  // of that class
  // Variance of the most probable class' probability: Dirichlet variance for S-BKI/S-CSM,
  // Bernoulli p(1-p) for the log-odds map.
  float variance = 0.0f;
  float occupancy = 0.5f;  // occupancy probability (log-odds map) or 1 - p(free) (S-BKI)
};

// Interprets fused channels (see LayeredMap::fused). S-BKI/S-CSM treat class 0 as free space.
CellSummary summarize(const MapParams& params, std::span<const float> fused);

// Probability of each of the K classes of a fused cell.
std::vector<double> class_probabilities(const MapParams& params, std::span<const float> fused);

}  // namespace semap::mapping
