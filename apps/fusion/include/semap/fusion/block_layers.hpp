#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "semap/dds_idl/block_snapshot.hpp"
#include "semap/dds_idl/map_description.hpp"
#include "semap/mapping/layered_map.hpp"

namespace semap::fusion {

// Conversions between the DDS form of a map block (dds_idl::BlockSnapshot) and the mapping
// library's layered maps. Both lay out a block's cells x fastest, then y, then z, and the
// evidence of a cell as K adjacent floats alpha - alpha_0, so blocks convert by copying.

// Map parameters of an S-BKI/S-CSM map with the shape of `description`; throws
// std::invalid_argument when the block side is not a power of two or `method` is log-odds
// (DDS blocks carry Dirichlet evidence only).
mapping::MapParams map_params_of(const dds_idl::MapDescription& description,
                                 mapping::MapMethod method, double prior);

// The block's evidence as a layer block; the block must carry evidence of `params`' shape
// (throws std::invalid_argument otherwise).
std::vector<float> evidence_block(const dds_idl::BlockSnapshot& block,
                                  const mapping::MapParams& params);

// The fused block `key` of `map` as a DDS block: evidence alpha - alpha_0 summed over the
// layers, state, argmax class and its variance as common::CellPosterior reads them
// (dds_idl::snapshot_of_evidence). Empty when no layer holds the block.
std::optional<dds_idl::BlockSnapshot> fused_snapshot(const mapping::LayeredMap& map,
                                                     const common::BlockIndex& key,
                                                     std::uint32_t version);

}  // namespace semap::fusion
