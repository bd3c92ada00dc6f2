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
#include "plane_tile.hpp"
#include "semap/mapping/block.hpp"
#include "semap/mapping/block_index.hpp"
#include "semap/mapping/kernel.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/mapping/semantic_map.hpp"
#include "semap/mapping/training_data.hpp"
#include "support_box.hpp"
#include "voxel_grouping.hpp"

namespace semap::mapping::detail {

// Training points and queries are dropped when their cell coordinates could overflow the
// block keys.
inline bool mappable(const Eigen::Vector3f& p, float inv_res) {
  constexpr float kLimit = static_cast<float>(1 << 20) - 64.0f;
  return p.allFinite() && (p.cwiseAbs() * inv_res).maxCoeff() < kLimit;
}

// What one insert touched, filled by TileInserter::insert.
struct TileInsertResult {
  std::size_t rejected_points = 0;
  std::vector<BlockIndex> updated_blocks;
  InsertPhases phases;  // all but `training`
};

// A tile is a cube of cells, the unit of parallel work: 32 cells per side (16 when such a
// scratch tile of K classes would exceed 512 KiB), or exactly one block when blocks have 8 or
// more cells per side, and for S-CSM. A toy training point's support (6 cells wide) reaches
// about 1.6 tiles of 32 instead of about 11 blocks of 4 cells, so the per-(point, piece)
// clipping runs far less often, and the scatter loop writes into a dense per-thread scratch
// tile (a PlaneTile, one plane per class) instead of finding the block of every row.
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
  // A point's support clipped to a tile, in tile-local cells, and its squared per-axis
  // distances from the clipped box's first cell on.
  struct Piece {
    CellBox box;
    std::array<const float*, 3> d2;
  };
  // A block of a tile: its position inside the tile (x fastest) and the block itself.
  struct TileBlock {
    std::uint32_t local;
    Block* block;
  };

  void prepare_points(const TrainingSet& training);
  void group_by_tile(std::size_t count);
  // Numbers the pairs' tiles by first occurrence (tiles_, pair_tile_ids_) with a linear
  // list; false when more than kFewTiles distinct tiles appear (then nothing is numbered).
  bool number_few_tiles(std::size_t pairs);
  void mark_blocks(std::size_t tile);
  void create_blocks(const BlockAt& block_at, TileInsertResult& result);
  void process_tile(std::size_t tile, const TrainingSet& training, const KernelTable& kernel);
  Piece piece_of(std::size_t i, const std::array<std::int32_t, 3>& base) const;
  void scatter_in_place(Block& block, const std::array<std::int32_t, 3>& base, std::size_t i,
                        const TrainingSet& training, const KernelTable& kernel) const;
  void write_back(PlaneTile& scratch, std::size_t tile) const;

  MapParams params_;
  KernelPolynomial polynomial_;  // the kernel of scratch tiles (blocks written in place: table)
  std::int32_t block_shift_;     // log2(cells per block side)
  std::int32_t tile_shift_;      // log2(cells per tile side)
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
  static constexpr std::size_t kFewTiles = 64;
  VoxelGrouping tile_grouping_;
  std::vector<std::uint32_t> pair_tile_ids_;  // per pair: its tile's number
  std::vector<BlockIndex> tiles_;
  std::vector<std::uint32_t> tile_offsets_;  // tiles_.size() + 1, into tile_points_
  std::vector<std::uint32_t> tile_points_;
  std::vector<std::uint64_t> block_masks_;  // mask_words_ per tile
  std::vector<std::uint32_t> fill_;
  std::vector<std::uint32_t> block_offsets_;  // tiles_.size() + 1, into tile_blocks_
  std::vector<TileBlock> tile_blocks_;
  std::vector<std::uint32_t> order_;                    // tiles in processing order
  tbb::enumerable_thread_specific<PlaneTile> scratch_;  // created on first use per thread
};

}  // namespace semap::mapping::detail
