#pragma once

#include <string>
#include <vector>

#include "../mapping/toy_dataset.hpp"
#include "semap/mapping/layered_map_params.hpp"

namespace semap::mapping::testing {

// The toy run's parameters (dataset README) for the log-odds map: 0.1 m, 4 classes, 8 m.
inline LayeredMapParams toy_logodds_params() {
  LayeredMapParams p;
  p.method = MapMethod::kLogOdds;
  p.resolution = 0.1;
  p.block_depth = 3;
  p.num_classes = 4;
  p.logodds.max_range = 8.0;
  return p;
}

}  // namespace semap::mapping::testing
