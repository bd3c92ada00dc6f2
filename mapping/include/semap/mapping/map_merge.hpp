#pragma once

#include <Eigen/Geometry>
#include <cstddef>

#include "semap/mapping/layered_map.hpp"

namespace semap::mapping {

struct MergeReport {
  std::size_t layers_added = 0;     // sources new to the target
  std::size_t layers_replaced = 0;  // sources whose incoming copy was newer
  std::size_t layers_kept = 0;      // sources the target already held as new or newer
};

// Resamples a layer from `from_params`' grid into `to_params`' grid: every target cell takes
// the evidence of the source cell its centre falls in under T_from_to = inverse(T_to_from),
// nearest-neighbour so classes and log-odds are copied, never blended. Identity transforms on
// equal grids copy blocks unchanged.
EvidenceGrid resample_layer(const EvidenceGrid& layer, const MapParams& from_params,
                            const MapParams& to_params, const Eigen::Isometry3d& T_to_from);

// Merges map `b` into map `a` given T_ab (B's frame to A's). Per source robot: a source `a`
// lacks is resampled into A's grid and added; a source both hold is replaced only when B's
// copy has integrated more scans (evidence only grows, so that copy is newer). Fused
// evidence therefore adds the robots' contributions (log-odds: occupancy and label log-odds;
// S-BKI/S-CSM: alpha_A + alpha_B - alpha_0) exactly once: merging the same map again, or
// merging A into B and B back into A, changes nothing.
// Throws std::invalid_argument when the maps' methods or class counts differ.
MergeReport merge_into(LayeredMap& a, const LayeredMap& b, const Eigen::Isometry3d& T_ab);

}  // namespace semap::mapping
