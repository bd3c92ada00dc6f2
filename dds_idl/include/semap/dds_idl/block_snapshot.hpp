#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace semap::dds_idl {

enum class CellState : std::uint8_t { kUnknown = 0, kFree = 1, kOccupied = 2 };

// Integer index of a cubic block; the block covers [index, index + 1) * block side in metres.
struct BlockIndex {
  std::int32_t x = 0;
  std::int32_t y = 0;
  std::int32_t z = 0;
  auto operator<=>(const BlockIndex&) const = default;
};

struct BlockIndexHash {
  std::size_t operator()(const BlockIndex& b) const {
    // Large primes spread neighbouring blocks over the buckets.
    return static_cast<std::size_t>(b.x) * 73856093u ^ static_cast<std::size_t>(b.y) * 19349663u ^
           static_cast<std::size_t>(b.z) * 83492791u;
  }
};

// One block of the semantic map as the map publishes it: the plain C++ form of
// semap_msgs/SemanticMapBlock, independent of the mapping library. Cells are ordered x fastest,
// then y, then z. `evidence` is empty or holds cell_count() * num_classes Dirichlet evidence
// values alpha - alpha_0 (the prior left out, as the mapping library stores them), cell-major.
struct BlockSnapshot {
  BlockIndex index;
  float resolution = 0.1f;        // cell edge, m
  std::uint16_t block_cells = 8;  // cells along one block edge
  std::uint16_t num_classes = 0;
  std::uint32_t version = 0;  // bumped by the producer at each change of the block
  std::vector<CellState> state;
  std::vector<std::uint16_t> argmax_class;
  std::vector<float> variance;
  std::vector<float> evidence;

  // An all-unknown block of the given shape.
  static BlockSnapshot empty(BlockIndex index, float resolution, std::uint16_t block_cells,
                             std::uint16_t num_classes, bool with_evidence);

  std::size_t cell_count() const {
    return static_cast<std::size_t>(block_cells) * block_cells * block_cells;
  }
  bool has_evidence() const { return !evidence.empty(); }
  float block_side() const { return resolution * static_cast<float>(block_cells); }
  Eigen::Vector3f origin() const;
  Eigen::Vector3f cell_center(std::size_t cell) const;
};

// The block holding `p` and the cell within it, for a map of the given cell and block size.
BlockIndex block_of(const Eigen::Vector3f& p, float resolution, std::uint16_t block_cells);
std::size_t cell_of(const Eigen::Vector3f& p, const BlockIndex& block, float resolution,
                    std::uint16_t block_cells);

}  // namespace semap::dds_idl
