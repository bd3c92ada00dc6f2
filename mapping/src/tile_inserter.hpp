#pragma once

// Internal to semap_mapping: the insertion engine behind SemanticMap::insert.

#include <tbb/enumerable_thread_specific.h>

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "fast_floor.hpp"
#include "semap/mapping/block.hpp"
#include "semap/mapping/block_index.hpp"
#include "semap/mapping/kernel.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/mapping/training_data.hpp"
#include "voxel_grouping.hpp"

namespace semap::mapping::detail {

// Training points and queries are dropped when their cell coordinates could overflow the
// block keys.
inline bool mappable(const Eigen::Vector3f& p, float inv_res) {
  constexpr float kLimit = static_cast<float>(1 << 20) - 64.0f;
  return p.allFinite() && (p.cwiseAbs() * inv_res).maxCoeff() < kLimit;
}

// Inclusive range of cell coordinates per axis; empty when lo > hi.
struct CellBox {
  std::array<std::int32_t, 3> lo;
  std::array<std::int32_t, 3> hi;
};

// Where a tile's weights go: cell-major evidence of side^3 cells (cell (z side + y) side + x)
// and the observed bits of each row of side cells, either as row masks of the scratch tile or,
// when the tile is one block, as the block's own bits.
struct TileTarget {
  float* evidence;
  std::uint32_t* rows;  // scratch row masks, or nullptr to mark `block`
  Block* block;

  void mark(std::size_t row, std::uint32_t bits, std::int32_t side) const {
    if (rows != nullptr) {
      rows[row] |= bits;
    } else {
      // A row of n <= 32 cells starts at a multiple of n, so it lies in one 64-bit word.
      const std::size_t cell = row * static_cast<std::size_t>(side);
      block->mark_observed_word(static_cast<int>(cell >> 6), std::uint64_t{bits} << (cell & 63));
    }
  }
};

// What one insert touched, filled by TileInserter::insert.
struct TileInsertResult {
  std::size_t rejected_points = 0;
  std::vector<BlockIndex> updated_blocks;
};

// A tile is a cube of cells, the unit of parallel work: 32 cells per side (16 when such a
// scratch tile of K classes would exceed 512 KiB), or exactly one block when blocks have 8 or
// more cells per side, and for S-CSM. A toy training point's support (6 cells wide) reaches
// about 1.6 tiles of 32 instead of about 11 blocks of 4 cells, so the per-(point, piece)
// clipping runs far less often, and the scatter loop writes into a dense per-thread scratch
// tile (same cell-major layout as a block) instead of finding the block of every row.
//
// Every tile is processed by one task that visits its points in input order. With a scratch
// tile it adds their weights into the zeroed scratch, then adds the scratch to the tile's
// blocks and zeroes it again: per cell, evidence + (this scan's weights summed in input
// order). A one-block tile is written in place. Neither depends on the thread count.
class TileInserter {
 public:
  using BlockAt = std::function<Block&(const BlockIndex&)>;

  explicit TileInserter(const MapParams& params);

  // Fuses `training`; points with a bad label or unmappable coordinates are rejected and
  // counted. `block_at` returns the block at an index, creating it; it is called serially
  // before the parallel part.
  TileInsertResult insert(const TrainingSet& training, const KernelTable& kernel,
                          const BlockAt& block_at);

 private:
  // Per-thread scratch of one tile: tile_side^3 cells of K floats, and one bit mask per
  // row of tile_side cells saying which cells got a weight (they are the observed ones and
  // the only non-zero scratch cells).
  struct Scratch {
    std::vector<float> evidence;
    std::vector<std::uint32_t> rows;
  };
  // A block of a tile: its position inside the tile (x fastest) and the block itself.
  struct TileBlock {
    std::uint32_t local;
    Block* block;
  };

  void prepare_points(const TrainingSet& training);
  void group_by_tile(std::size_t count);
  void mark_blocks(std::size_t tile);
  void create_blocks(const BlockAt& block_at, TileInsertResult& result);
  void process_tile(std::size_t tile, const TrainingSet& training, const KernelTable& kernel);
  void scatter_point(const TileTarget& target, const std::array<std::int32_t, 3>& base,
                     std::size_t i, const TrainingSet& training, const KernelTable& kernel) const;
  void write_back(Scratch& scratch, std::size_t tile) const;

  MapParams params_;
  std::int32_t block_shift_;  // log2(cells per block side)
  std::int32_t tile_shift_;   // log2(cells per tile side)
  std::int32_t blocks_per_tile_side_;
  std::size_t mask_words_;  // 64-bit words of a tile's block mask
  std::size_t width_;       // distances stored per point and axis

  // Per-scan buffers, kept across scans to avoid reallocating them.
  std::vector<CellBox> boxes_;             // support of each training point (empty if unusable)
  std::vector<float> distances_;           // S-BKI: squared axis distances, 3 * width_ per point
  std::vector<std::uint8_t> bad_;          // 1 for rejected points
  std::vector<std::uint32_t> pair_first_;  // count + 1: first (point, tile) pair of each point
  std::vector<BlockIndex> pair_tiles_;
  std::vector<std::uint32_t> pair_points_;
  VoxelGrouping tile_grouping_;
  std::vector<BlockIndex> tiles_;
  std::vector<std::uint32_t> tile_offsets_;  // tiles_.size() + 1, into tile_points_
  std::vector<std::uint32_t> tile_points_;
  std::vector<std::uint64_t> block_masks_;  // mask_words_ per tile
  std::vector<std::uint32_t> fill_;
  std::vector<std::uint32_t> block_offsets_;  // tiles_.size() + 1, into tile_blocks_
  std::vector<TileBlock> tile_blocks_;
  std::vector<std::uint32_t> order_;  // tiles in processing order
  tbb::enumerable_thread_specific<Scratch> scratch_;
};

}  // namespace semap::mapping::detail
