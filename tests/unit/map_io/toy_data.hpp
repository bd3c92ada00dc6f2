#pragma once

#include <string>
#include <vector>

#include "../mapping/toy_dataset.hpp"
#include "semap/mapping/map_params.hpp"

namespace semap::mapping::testing {

// The toy run's parameters (dataset README) for the log-odds map: 0.1 m, 4 classes, 8 m.
inline MapParams toy_logodds_params() {
  MapParams p;
  p.method = MapMethod::kLogOdds;
  p.resolution = 0.1f;
  p.block_depth = 3;
  p.num_classes = 4;
  p.logodds.max_range = 8.0;
  return p;
}

}  // namespace semap::mapping::testing
