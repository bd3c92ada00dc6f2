#pragma once

#include <string>
#include <vector>

#include "semap/map_io/pcd_io.hpp"

namespace semap::mapping::testing {

// Scans first..last (1-based) of the S-BKI paper's toy dataset in ../shared.
inline std::vector<common::LabeledCloud> toy_scans(int first, int last) {
  std::vector<common::LabeledCloud> scans;
  for (int i = first; i <= last; ++i) {
    scans.push_back(map_io::read_pcd(std::string(SEMAP_SHARED_DATA_DIR) +
                                     "/sim_unstructured_annotated/sim_unstructured_annotated_" +
                                     std::to_string(i) + ".pcd")
                        .cloud);
  }
  return scans;
}

}  // namespace semap::mapping::testing
