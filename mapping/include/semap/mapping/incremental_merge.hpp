#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "semap/mapping/layered_map.hpp"

namespace semap::mapping {

// Re-merging only what changed. merge_into resamples a robot's whole layer, which
// grows with the robot's map; when a few blocks of a layer change, only the target blocks
// they reach need resampling, from the source blocks that reach those. The result is the
// same as merge_into of the whole layer (tests/unit/fusion checks it under random rigid
// transforms); the resampling itself is resample_layer.

// Blocks of the target grid whose cells can take evidence from source block `key` when a
// layer is resampled with T_to_from (a target cell takes the source cell its centre falls
// in). A superset, exact for grid-aligned transforms.
std::vector<common::BlockIndex> touched_blocks(const common::BlockIndex& key, const MapParams& from,
                                               const MapParams& to,
                                               const Eigen::Isometry3d& T_to_from);

// Source blocks holding the cells that target block `key`'s cell centres fall in: everything
// resampling needs to rebuild that target block. A superset, exact for grid-aligned
// transforms.
std::vector<common::BlockIndex> source_blocks(const common::BlockIndex& key, const MapParams& from,
                                              const MapParams& to,
                                              const Eigen::Isometry3d& T_to_from);

// Rebuilds the blocks `targets` of `source`'s layer in `fused` from `layer` (in the grid of
// `from`, placed by T_to_from) and takes over the layer's update count. Target blocks left
// without evidence are removed from that layer.
void remerge_blocks(LayeredMap& fused, SourceId source, const EvidenceGrid& layer,
                    const MapParams& from, const std::vector<common::BlockIndex>& targets,
                    const Eigen::Isometry3d& T_to_from);

}  // namespace semap::mapping
