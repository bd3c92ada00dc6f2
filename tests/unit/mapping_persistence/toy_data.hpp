#pragma once

#include <string>
#include <vector>

#include "semap/mapping/layered_map_params.hpp"
#include "semap/mapping/pcd_io.hpp"

namespace semap::mapping::testing {

// Scans first..last (1-based) of the S-BKI paper's toy dataset.
inline std::vector<common::LabeledCloud> toy_scans(int first, int last) {
  std::vector<common::LabeledCloud> scans;
  for (int i = first; i <= last; ++i) {
    scans.push_back(read_pcd(std::string(SEMAP_SHARED_DATA_DIR) +
                             "/sim_unstructured_annotated/sim_unstructured_annotated_" +
                             std::to_string(i) + ".pcd")
                        .cloud);
  }
  return scans;
}

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
