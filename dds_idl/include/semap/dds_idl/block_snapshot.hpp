#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "semap/common/map_grid.hpp"

namespace semap::dds_idl {

// One block of the semantic map as the map publishes it: the plain C++ form of
// semap_msgs/SemanticMapBlock, independent of the mapping library. Cells are ordered x fastest,
// then y, then z. `evidence` is empty or holds cell_count() * num_classes Dirichlet evidence
// values alpha - alpha_0 (the prior left out, as the mapping library stores them), cell-major.
struct BlockSnapshot {
  common::BlockIndex index;
  float resolution = 0.1f;        // cell edge, m
  std::uint16_t block_cells = 8;  // cells along one block edge
  std::uint16_t num_classes = 0;
  std::uint32_t version = 0;  // bumped by the producer at each change of the block
  std::vector<common::CellState> state;
  std::vector<std::uint16_t> argmax_class;
  std::vector<float> variance;
  std::vector<float> evidence;

  // An all-unknown block of the given shape.
  static BlockSnapshot empty(common::BlockIndex index, float resolution, std::uint16_t block_cells,
                             std::uint16_t num_classes, bool with_evidence);

  std::size_t cell_count() const {
    return static_cast<std::size_t>(block_cells) * block_cells * block_cells;
  }
  bool has_evidence() const { return !evidence.empty(); }
  float block_side() const { return resolution * static_cast<float>(block_cells); }
  common::MapGrid grid() const { return {resolution, block_cells}; }
  Eigen::Vector3f origin() const;
  Eigen::Vector3f cell_center(std::size_t cell) const;
};

// A block of an S-BKI / S-CSM map as published, read from its Dirichlet evidence (K values
// alpha - alpha_0 per cell, cell-major) with common::CellPosterior: each cell's state, argmax
// class and that class's variance, the evidence kept. `observed` holds one flag per cell; when
// empty, a cell with positive evidence counts as observed (a fused or merged map).
BlockSnapshot snapshot_of_evidence(common::BlockIndex index, const common::MapGrid& grid,
                                   int num_classes, std::span<const float> evidence,
                                   std::span<const std::uint8_t> observed, float prior,
                                   float unknown_variance, std::uint32_t version);
// The same into `out`, reusing its buffers; without `with_evidence`, out.evidence is left empty
// (a map cloud needs only the cells).
void snapshot_of_evidence(common::BlockIndex index, const common::MapGrid& grid, int num_classes,
                          std::span<const float> evidence, std::span<const std::uint8_t> observed,
                          float prior, float unknown_variance, std::uint32_t version,
                          bool with_evidence, BlockSnapshot& out);

}  // namespace semap::dds_idl
