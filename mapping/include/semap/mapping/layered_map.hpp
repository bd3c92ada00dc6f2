#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <vector>

#include "semap/mapping/evidence_grid.hpp"
#include "semap/mapping/map_params.hpp"

namespace semap::mapping {

// Identifies the robot that contributed a layer of evidence.
using SourceId = std::uint32_t;

// A map as a set of evidence layers, one per source robot, all in this map's grid. Keeping
// each robot's evidence apart is what lets merging stay free of double counting: merging a
// layer that is already present replaces it instead of adding it again.
//
// Fused evidence of a cell (the map a user sees):
//   log-odds: occupancy clamp(sum_s occ_s), label log-odds sum_s l_s;
//   S-BKI/S-CSM: alpha = alpha_0 + sum_s (alpha_s - alpha_0), the layers holding increments.
class LayeredMap {
 public:
  explicit LayeredMap(const MapParams& params);

  const MapParams& params() const { return params_; }

  // The layer of `source`, created empty on first use.
  EvidenceGrid& layer(SourceId source);
  const EvidenceGrid* find_layer(SourceId source) const;
  const std::map<SourceId, EvidenceGrid>& layers() const { return layers_; }
  // Replaces the layer of `source`; its geometry must match this map's parameters.
  void set_layer(SourceId source, EvidenceGrid grid);
  void erase_layer(SourceId source) { layers_.erase(source); }

  // Writes the fused channels of `cell` into `out` (channels() floats); returns false (and
  // leaves the prior in `out`) when no layer has evidence there.
  bool fused(const common::CellIndex& cell, std::span<float> out) const;
  // Fused channels of a whole block (cells_per_block x channels); false if no layer has it.
  bool fused_block(const common::BlockIndex& key, std::vector<float>& out) const;
  // Union of the block keys of all layers.
  std::vector<common::BlockIndex> block_keys() const;
  // Blocks over all layers (what a memory budget counts).
  std::size_t resident_blocks() const;

  EvidenceGrid make_grid() const {
    return EvidenceGrid(params_.cells_per_side(), params_.channels());
  }

  bool operator==(const LayeredMap& other) const = default;

 private:
  void fuse_into(std::span<const float> layer, std::span<float> out) const;
  void finish_fusion(std::span<float> out) const;

  MapParams params_;
  std::map<SourceId, EvidenceGrid> layers_;
};

}  // namespace semap::mapping
