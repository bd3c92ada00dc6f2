#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <span>
#include <vector>

#include "semap/common/map_grid.hpp"
#include "semap/mapping/block.hpp"
#include "semap/mapping/voxel_hash_map.hpp"

namespace semap::mapping {

// The one store of map blocks: a sparse grid of Blocks of block_side^3 cells x `channels`
// floats. The live S-BKI/S-CSM map inserts into it, the log-odds map writes its cells, and
// saving, merging, paging, export and fusion read it; none of them keeps a copy. A cell never
// touched reads as all zeros, which every cell model uses as "no evidence".
//
// Blocks are found through an open-addressing table (coordinates within +-2^20 blocks) and keep
// their address while others are added, so the insertion engine can write many blocks in
// parallel once it has created them. A pager may evict a block (written elsewhere first) and
// restore it later.
class EvidenceGrid {
 public:
  EvidenceGrid(int block_side, int channels);
  ~EvidenceGrid();
  // Copies the blocks in memory (not those evicted).
  EvidenceGrid(const EvidenceGrid& other);
  EvidenceGrid& operator=(const EvidenceGrid& other);
  EvidenceGrid(EvidenceGrid&&) noexcept;
  EvidenceGrid& operator=(EvidenceGrid&&) noexcept;

  int block_side() const { return block_side_; }
  int cells_per_block() const { return block_side_ * block_side_ * block_side_; }
  int channels() const { return channels_; }
  std::size_t block_floats() const {
    return static_cast<std::size_t>(cells_per_block()) * static_cast<std::size_t>(channels_);
  }
  static bool in_range(const common::BlockIndex& key) { return VoxelHashMap::in_range(key); }

  // The block at `key`, created with zero evidence if it is not in memory (an evicted block
  // starts again from zero: restore it first). Throws std::invalid_argument beyond +-2^20.
  Block& block_at(const common::BlockIndex& key);
  // The block at `key` if it is in memory.
  const Block* find_block(const common::BlockIndex& key) const;
  Block* find_block(const common::BlockIndex& key);

  // Reads the channels of one cell into `out` (channels() floats); false, with `out` zeroed,
  // when its block is not in memory.
  bool read_cell(const common::CellIndex& cell, std::span<float> out) const;
  // Replaces the channels of one cell, creating its block and marking the cell observed.
  void set_cell(const common::CellIndex& cell, std::span<const float> values);

  // Adds `evidence` (block_floats() values) to the block at `key`, creating it; cells given a
  // non-zero value become observed. Throws std::invalid_argument for a wrong count or range.
  void add_block(const common::BlockIndex& key, std::span<const float> evidence);
  // Replaces the block at `key` with `evidence` (observed where non-zero). Throws as add_block.
  void put_block(const common::BlockIndex& key, std::span<const float> evidence);
  // Adds evidence and observed bits exactly as written out (Block::restore). Throws as add_block.
  void restore_block(const common::BlockIndex& key, std::span<const float> evidence,
                     std::span<const std::uint64_t> observed);
  // Drops the block at `key` from memory; false when it is not in memory.
  bool evict(const common::BlockIndex& key);

  // Calls f(const common::BlockIndex&, const Block&) for every block in memory, in the order
  // they were first created.
  template <typename F>
  void for_each_block(F&& f) const {
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      if (resident_[b]) f(keys_[b], blocks_[b]);
    }
  }
  std::vector<common::BlockIndex> keys() const;
  std::size_t size() const { return blocks_.size() - evicted_; }  // blocks in memory
  std::size_t evicted() const { return evicted_; }
  // Heap bytes: the blocks (their entries and observed bits) and the block table.
  std::size_t bytes() const;

  // Number of scans integrated into this grid; orders two copies of one robot's evidence
  // (evidence only grows, so the copy with more updates is the newer one).
  std::uint64_t updates() const { return updates_; }
  void set_updates(std::uint64_t updates) { updates_ = updates; }

  // Same geometry, update count, blocks in memory and evidence (observed bits are derived).
  bool operator==(const EvidenceGrid& other) const;

 private:
  void check_block(const common::BlockIndex& key, std::span<const float> evidence) const;

  int block_side_;
  int channels_;
  std::uint64_t updates_ = 0;
  VoxelHashMap table_{16};                // block key -> position in blocks_ (grows)
  std::vector<common::BlockIndex> keys_;  // per position
  std::deque<Block> blocks_;              // a deque: references stay valid as blocks are added
  std::vector<std::uint8_t> resident_;    // per position: 0 once evicted
  std::size_t evicted_ = 0;
};

}  // namespace semap::mapping
