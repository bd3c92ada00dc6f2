#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <unordered_map>
#include <vector>

#include "semap/common/map_grid.hpp"

namespace semap::mapping {

// Sparse grid of blocks, each a dense contiguous array of block_side^3 cells x `channels`
// floats (cell-major: the channels of one cell are adjacent). A cell never touched reads as
// all zeros, which every map method uses as "no evidence".
class EvidenceGrid {
 public:
  using Block = std::vector<float>;
  using BlockMap = std::unordered_map<common::BlockIndex, Block, common::BlockIndexHash>;

  EvidenceGrid(int block_side, int channels);

  int block_side() const { return block_side_; }
  int cells_per_block() const { return block_side_ * block_side_ * block_side_; }
  int channels() const { return channels_; }
  std::size_t block_floats() const {
    return static_cast<std::size_t>(cells_per_block()) * static_cast<std::size_t>(channels_);
  }

  // Channels of one cell, allocating its block (zero-filled) on first use.
  std::span<float> cell(const common::CellIndex& cell);
  // Channels of one cell, or an empty span when its block does not exist.
  std::span<const float> find(const common::CellIndex& cell) const;

  const BlockMap& blocks() const { return blocks_; }
  const Block* find_block(const common::BlockIndex& key) const;
  // Replaces the block at `key`; `block` must hold block_floats() values.
  void put_block(const common::BlockIndex& key, Block block);
  // Removes and returns the block at `key`, if any.
  std::optional<Block> take_block(const common::BlockIndex& key);
  std::size_t size() const { return blocks_.size(); }

  // Number of scans integrated into this grid; orders two copies of one robot's evidence
  // (evidence only grows, so the copy with more updates is the newer one).
  std::uint64_t updates() const { return updates_; }
  void set_updates(std::uint64_t updates) { updates_ = updates; }

  bool operator==(const EvidenceGrid& other) const = default;

 private:
  int block_side_;
  int channels_;
  std::uint64_t updates_ = 0;
  BlockMap blocks_;
};

}  // namespace semap::mapping
