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
#include "mappable.hpp"
#include "plane_tile.hpp"
#include "semap/common/map_grid.hpp"
#include "semap/mapping/bki_update.hpp"
#include "semap/mapping/block.hpp"
#include "semap/mapping/block_delta.hpp"
#include "semap/mapping/kernel.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/mapping/semantic_map.hpp"
#include "semap/mapping/training_data.hpp"
#include "support_box.hpp"
#include "voxel_grouping.hpp"

namespace semap::mapping::detail {

// The block at an index if the map holds it (resident), else nullptr; called from several
// threads at once while the map is not changed.
using BlockFind = std::function<Block*(const common::BlockIndex&)>;

// What one insert touched, filled by TileInserter::insert.
struct TileInsertResult {
  std::size_t rejected_points = 0;
  std::vector<common::BlockIndex> updated_blocks;
  InsertPhases phases;  // all but `training`
};

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

// Everything one scan's insertion needs that does not depend on the map: the points'
// supports and distances and their grouping into tiles (TileInserter::plan), plus the tiles'
// blocks once they exist (TileInserter::apply). Kept across scans to reuse the buffers.
struct TilePlan {
  std::vector<CellBox> boxes;     // support of each training point (empty if unusable)
  std::vector<float> distances;   // one-block tiles: squared axis distances, 3 * width_ per point
  std::vector<std::uint8_t> bad;  // 1 for rejected points
  std::size_t rejected_points = 0;
  std::vector<std::uint32_t> pair_first;  // count + 1: first (point, tile) pair of each point
  std::vector<common::BlockIndex> pair_tiles;
  std::vector<std::uint32_t> pair_points;
  VoxelGrouping tile_grouping;
  std::vector<std::uint32_t> pair_tile_ids;  // per pair: its tile's number
  std::vector<std::uint32_t> dense_ids;      // number_dense_tiles' table
  std::vector<common::BlockIndex> tiles;
  std::vector<std::uint32_t> tile_offsets;  // tiles.size() + 1, into tile_points
  std::vector<std::uint32_t> tile_points;
  std::vector<std::uint64_t> block_masks;  // mask_words_ per tile
  std::vector<std::uint32_t> fill;
  std::vector<std::uint32_t> order;          // tiles in processing order
  std::vector<std::uint32_t> block_offsets;  // tiles.size() + 1, into tile_blocks (apply)
  std::vector<TileBlock> tile_blocks;
  InsertPhases phases;  // prepare and group
};

// A tile is a cube of cells, the unit of parallel work: 32 cells per side (16 when such a
// scratch tile of K classes would exceed 512 KiB), or exactly one block when blocks have 8 or
// more cells per side, and for S-CSM. A toy training point's support (6 cells wide) reaches
// about 1.6 tiles of 32 instead of about 11 blocks of 4 cells, so the per-(point, piece)
// clipping runs far less often, and the scatter loop writes into a dense per-thread scratch
// tile (a PlaneTile, one plane per class) instead of finding the block of every row.
//
// Every tile is processed by one task that visits its points in input order. With a scratch
// tile it adds their weights into the zeroed scratch, then moves each block's part into a
// BlockDelta and merges that into the block; a one-block tile adds them into the delta
// directly. Either way, per cell: evidence + (this scan's weights summed in input order),
// independent of the thread count.
class TileInserter {
 public:
  explicit TileInserter(const MapParams& params);

  // Fuses `training`: plan() then apply(). Points with a bad label or unmappable coordinates
  // are rejected and counted. `block_at` returns the block at an index, creating it; it is
  // called serially before the parallel part, for the blocks that `find` did not return.
  TileInsertResult insert(const TrainingSet& training, const BlockAt& block_at,
                          const BlockFind& find);
  // The map-independent part of insert: may run for a later scan (any number at once, each
  // with its own plan) while apply() fuses an earlier one.
  void plan(const TrainingSet& training, TilePlan& plan) const;
  // Creates the plan's missing blocks and adds the training set's weights to the map.
  TileInsertResult apply(TilePlan& plan, const TrainingSet& training, const BlockAt& block_at,
                         const BlockFind& find);

 private:
  void prepare_points(const TrainingSet& training, TilePlan& plan) const;
  void group_by_tile(std::size_t count, TilePlan& plan) const;
  // Numbers the pairs' tiles by first occurrence (tiles, pair_tile_ids) with a linear
  // list; false when more than kFewTiles distinct tiles appear (then nothing is numbered).
  bool number_few_tiles(std::size_t pairs, TilePlan& plan) const;
  // The same through a dense table over the tiles' bounding box; false when that box holds
  // more than kDenseTiles tiles (then nothing is numbered).
  bool number_dense_tiles(std::size_t pairs, TilePlan& plan) const;
  void mark_blocks(std::size_t tile, TilePlan& plan) const;
  void create_blocks(TilePlan& plan, const BlockAt& block_at, const BlockFind& find,
                     TileInsertResult& result) const;
  void process_tile(const TilePlan& plan, std::size_t tile, const TrainingSet& training);
  Piece piece_of(const TilePlan& plan, std::size_t i,
                 const std::array<std::int32_t, 3>& base) const;
  void scatter_in_place(const TilePlan& plan, BlockDelta& delta,
                        const std::array<std::int32_t, 3>& base, std::size_t i,
                        const TrainingSet& training) const;
  void write_back(const TilePlan& plan, PlaneTile& scratch, std::size_t tile);

  MapParams params_;
  KernelPolynomial polynomial_;  // the one kernel approximation, of every block size
  std::int32_t block_shift_;     // log2(cells per block side)
  std::int32_t tile_shift_;      // log2(cells per tile side)
  std::int32_t blocks_per_tile_side_;
  std::size_t mask_words_;  // 64-bit words of a tile's block mask
  std::size_t width_;       // distances stored per point and axis
  static constexpr std::size_t kFewTiles = 64;
  static constexpr std::size_t kDenseTiles = std::size_t{1} << 22;

  TilePlan plan_;                                       // of insert()
  tbb::enumerable_thread_specific<PlaneTile> scratch_;  // created on first use per thread
  tbb::enumerable_thread_specific<BlockDelta> deltas_;  // one block's sums, per thread
};

}  // namespace semap::mapping::detail
