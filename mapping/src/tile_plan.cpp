// The map-independent half of TileInserter (TileInserter::plan): each training point's
// support, the (point, tile) pairs, the tiles' numbering and points, and the blocks of each
// tile that supports overlap.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>

#include "axis_distances.hpp"
#include "phase_clock.hpp"
#include "tile_inserter.hpp"

namespace semap::mapping::detail {

namespace {

// Cells a training point touches: for S-BKI all cells whose centre lies within ell per
// axis (rows are trimmed to the sphere in the scatter loop), for S-CSM the cell containing
// the point.
// What support_of needs from the parameters, copied into the per-point loop: there, stores
// into the plan's arrays could alias MapParams' fields and would force a reload per point.
struct SupportRule {
  bool csm;
  float ell;
  float inv_res;
};

SupportRule support_rule(const MapParams& params) {
  return {params.method == MapMethod::kCsm, params.ell, 1.0f / params.resolution};
}

CellBox support_of(const Eigen::Vector3f& p, const SupportRule& rule) {
  CellBox box{};
  if (rule.csm) {
    for (int a = 0; a < 3; ++a) box.lo[a] = box.hi[a] = fast_floor(p[a] * rule.inv_res);
    return box;
  }
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = fast_ceil((p[a] - rule.ell) * rule.inv_res - 0.5f);
    box.hi[a] = fast_floor((p[a] + rule.ell) * rule.inv_res - 0.5f);
  }
  return box;
}

bool empty(const CellBox& box) {
  return box.lo[0] > box.hi[0] || box.lo[1] > box.hi[1] || box.lo[2] > box.hi[2];
}

constexpr CellBox kEmptyBox{{0, 0, 0}, {-1, -1, -1}};

// Points per parallel chunk of the per-point preparation.
constexpr std::size_t kPointGrain = 1024;

}  // namespace

void TileInserter::prepare_points(const TrainingSet& training, TilePlan& plan) const {
  const std::size_t count = training.size();
  plan.boxes.resize(count);
  plan.bad.resize(count);
  // Padded so that the row test may read 8 floats from any cell of the last point.
  plan.distances.resize(count * 3 * width_ + 8);
  // Locals and raw pointers: the loop's stores would otherwise make the compiler reload the
  // members and vector pointers they might alias for every point.
  const SupportRule rule = support_rule(params_);
  const float resolution = params_.resolution;
  const std::int32_t classes = params_.num_classes;
  const std::size_t width = width_;
  const std::size_t soft_rows = training.probabilities.size() / params_.num_classes;
  const Eigen::Vector3f* points = training.points.data();
  const std::int32_t* labels = training.labels.data();
  CellBox* boxes = plan.boxes.data();
  std::uint8_t* bad = plan.bad.data();
  float* distances = plan.distances.data();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, kPointGrain),
                    [=](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const std::int32_t label = labels[i];
                        const bool label_ok = label >= 0 ? label < classes : i < soft_rows;
                        const Eigen::Vector3f& p = points[i];
                        if (!label_ok || !mappable(p, rule.inv_res)) {
                          bad[i] = 1;
                          boxes[i] = kEmptyBox;
                          continue;
                        }
                        bad[i] = 0;
                        const CellBox box = support_of(p, rule);
                        boxes[i] = box;
                        if (width == 0) continue;
                        float* d2 = distances + i * 3 * width;
                        for (int a = 0; a < 3; ++a, d2 += width) {
                          axis_distances(box.lo[a], box.hi[a], p[a], resolution, d2);
                        }
                      }
                    });
}

void TileInserter::group_by_tile(std::size_t count, TilePlan& plan) const {
  const std::int32_t ts = tile_shift_;
  // 1. Tiles per point (parallel), then where each point's (point, tile) pairs start.
  plan.pair_first.assign(count + 1, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, kPointGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const CellBox& box = plan.boxes[i];
                        std::uint32_t tiles = empty(box) ? 0 : 1;
                        for (int a = 0; a < 3 && tiles; ++a) {
                          tiles *=
                              static_cast<std::uint32_t>((box.hi[a] >> ts) - (box.lo[a] >> ts) + 1);
                        }
                        plan.pair_first[i + 1] = tiles;
                      }
                    });
  for (std::size_t i = 0; i < count; ++i) plan.pair_first[i + 1] += plan.pair_first[i];
  const std::size_t pairs = plan.pair_first[count];
  // 2. The tile of every pair, in point order (parallel).
  plan.pair_tiles.resize(pairs);
  plan.pair_points.resize(pairs);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, kPointGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) {
                        const CellBox& box = plan.boxes[i];
                        std::size_t j = plan.pair_first[i];
                        if (j == plan.pair_first[i + 1]) continue;
                        for (std::int32_t tz = box.lo[2] >> ts; tz <= box.hi[2] >> ts; ++tz) {
                          for (std::int32_t ty = box.lo[1] >> ts; ty <= box.hi[1] >> ts; ++ty) {
                            for (std::int32_t tx = box.lo[0] >> ts; tx <= box.hi[0] >> ts;
                                 ++tx, ++j) {
                              plan.pair_tiles[j] = common::BlockIndex{tx, ty, tz};
                              plan.pair_points[j] = static_cast<std::uint32_t>(i);
                            }
                          }
                        }
                      }
                    });
  // 3. Tiles numbered by first occurrence: scratch tiles are few (toy: 8..18 per scan), so a
  // short list searched from the last hit beats hashing every pair; more of them (a LiDAR
  // scan: thousands) lie in a box small enough for a table indexed by position; many tiles
  // spread wide (blocks written in place) take parallel hash shards.
  const bool numbered = tile_shift_ != block_shift_ &&
                        (number_few_tiles(pairs, plan) || number_dense_tiles(pairs, plan));
  if (!numbered) {
    plan.tile_grouping.group(plan.pair_tiles, {});
    const auto ids = plan.tile_grouping.voxel_of();
    plan.pair_tile_ids.assign(ids.begin(), ids.end());
    plan.tiles.clear();
    for (std::size_t j = 0; j < pairs; ++j) {
      if (plan.pair_tile_ids[j] == plan.tiles.size()) plan.tiles.push_back(plan.pair_tiles[j]);
    }
  }
  std::vector<std::uint32_t>& counts = plan.fill;
  counts.assign(plan.tiles.size(), 0);
  for (std::size_t j = 0; j < pairs; ++j) ++counts[plan.pair_tile_ids[j]];
  // 4. Counting sort: each tile's points in ascending order.
  plan.tile_offsets.assign(plan.tiles.size() + 1, 0);
  for (std::size_t t = 0; t < plan.tiles.size(); ++t) {
    plan.tile_offsets[t + 1] = plan.tile_offsets[t] + counts[t];
  }
  plan.fill.assign(plan.tile_offsets.begin(), plan.tile_offsets.end() - 1);
  plan.tile_points.resize(pairs);
  for (std::size_t j = 0; j < pairs; ++j) {
    plan.tile_points[plan.fill[plan.pair_tile_ids[j]]++] = plan.pair_points[j];
  }
  // 5. Blocks of each tile that its points' supports overlap (parallel over tiles).
  if (tile_shift_ == block_shift_) {
    // A tile is one block, and every tile has a point.
    plan.block_masks.assign(plan.tiles.size(), 1);
    return;
  }
  plan.block_masks.assign(plan.tiles.size() * mask_words_, 0);
  tbb::parallel_for(std::size_t{0}, plan.tiles.size(),
                    [&](std::size_t t) { mark_blocks(t, plan); });
}

bool TileInserter::number_few_tiles(std::size_t pairs, TilePlan& plan) const {
  plan.tiles.clear();
  plan.pair_tile_ids.resize(pairs);
  // A point's pairs alternate between its 1..8 tiles, so remembering only the last tile sent
  // most pairs to the list search; a slot per hash of the tile finds nearly all of them.
  constexpr std::uint32_t kNoTile = 0xFFFFFFFFu;
  static_assert(kFewTiles == 64, "one slot per 6-bit hash below");
  std::array<std::uint32_t, kFewTiles> recent;
  recent.fill(kNoTile);
  for (std::size_t j = 0; j < pairs; ++j) {
    const common::BlockIndex& tile = plan.pair_tiles[j];
    const std::uint32_t slot = (static_cast<std::uint32_t>(tile.x) * 0x9E3779B1u ^
                                static_cast<std::uint32_t>(tile.y) * 0x85EBCA77u ^
                                static_cast<std::uint32_t>(tile.z) * 0xC2B2AE3Du) >>
                               26;
    std::uint32_t id = recent[slot];
    if (id == kNoTile || !(plan.tiles[id] == tile)) {
      id = 0;
      while (id < plan.tiles.size() && !(plan.tiles[id] == tile)) ++id;
      if (id == plan.tiles.size()) {
        if (id == kFewTiles) return false;
        plan.tiles.push_back(tile);
      }
      recent[slot] = id;
    }
    plan.pair_tile_ids[j] = id;
  }
  return true;
}

bool TileInserter::number_dense_tiles(std::size_t pairs, TilePlan& plan) const {
  if (pairs == 0) return false;
  std::array<std::int32_t, 3> lo{plan.pair_tiles[0].x, plan.pair_tiles[0].y, plan.pair_tiles[0].z};
  std::array<std::int32_t, 3> hi = lo;
  for (std::size_t j = 1; j < pairs; ++j) {
    const common::BlockIndex& t = plan.pair_tiles[j];
    lo = {std::min(lo[0], t.x), std::min(lo[1], t.y), std::min(lo[2], t.z)};
    hi = {std::max(hi[0], t.x), std::max(hi[1], t.y), std::max(hi[2], t.z)};
  }
  std::array<std::size_t, 3> extent{};
  for (int a = 0; a < 3; ++a) extent[a] = static_cast<std::size_t>(hi[a] - lo[a]) + 1;
  // Tile coordinates span at most 2^21 per axis; the product is tested one factor at a time.
  if (extent[0] > kDenseTiles || extent[1] > kDenseTiles / extent[0] ||
      extent[2] > kDenseTiles / (extent[0] * extent[1])) {
    return false;
  }
  constexpr std::uint32_t kNoTile = 0xFFFFFFFFu;
  plan.dense_ids.assign(extent[0] * extent[1] * extent[2], kNoTile);
  plan.tiles.clear();
  plan.pair_tile_ids.resize(pairs);
  for (std::size_t j = 0; j < pairs; ++j) {
    const common::BlockIndex& t = plan.pair_tiles[j];
    const std::size_t slot = (static_cast<std::size_t>(t.z - lo[2]) * extent[1] +
                              static_cast<std::size_t>(t.y - lo[1])) *
                                 extent[0] +
                             static_cast<std::size_t>(t.x - lo[0]);
    std::uint32_t& id = plan.dense_ids[slot];
    if (id == kNoTile) {
      id = static_cast<std::uint32_t>(plan.tiles.size());
      plan.tiles.push_back(t);
    }
    plan.pair_tile_ids[j] = id;
  }
  return true;
}

void TileInserter::mark_blocks(std::size_t tile, TilePlan& plan) const {
  const std::int32_t ts = tile_shift_;
  const std::int32_t bs = block_shift_;
  const std::int32_t t_side = blocks_per_tile_side_;
  const std::array<std::int32_t, 3> t{plan.tiles[tile].x, plan.tiles[tile].y, plan.tiles[tile].z};
  std::uint64_t* mask = plan.block_masks.data() + tile * mask_words_;
  for (std::uint32_t p = plan.tile_offsets[tile]; p < plan.tile_offsets[tile + 1]; ++p) {
    const CellBox& box = plan.boxes[plan.tile_points[p]];
    // Blocks of this tile that the support overlaps, in tile-local block units.
    std::array<std::int32_t, 3> blo{}, bhi{};
    for (int a = 0; a < 3; ++a) {
      const std::int32_t first = t[a] << ts;
      const std::int32_t last = first + (1 << ts) - 1;
      blo[a] = (std::max(box.lo[a], first) - first) >> bs;
      bhi[a] = (std::min(box.hi[a], last) - first) >> bs;
    }
    const std::uint64_t xbits =
        ((std::uint64_t{2} << bhi[0]) - 1) & ~((std::uint64_t{1} << blo[0]) - 1);
    if (t_side == 8) {
      // One word per z-slice of 8 x 8 blocks (toy: 32-cell tiles of 4-cell blocks): the
      // rows blo[1]..bhi[1] get xbits each, one multiplication (xbits < 2^8, no carries).
      constexpr std::uint64_t kRowStarts = 0x0101010101010101ull;
      const std::uint64_t rows = (kRowStarts >> (8 * (7 - (bhi[1] - blo[1])))) << (8 * blo[1]);
      for (std::int32_t bz = blo[2]; bz <= bhi[2]; ++bz) mask[bz] |= xbits * rows;
      continue;
    }
    for (std::int32_t bz = blo[2]; bz <= bhi[2]; ++bz) {
      for (std::int32_t by = blo[1]; by <= bhi[1]; ++by) {
        // A row of t_side <= 16 bits starts at a multiple of t_side: one word.
        const auto bit = static_cast<std::size_t>((bz * t_side + by) * t_side);
        mask[bit >> 6] |= xbits << (bit & 63);
      }
    }
  }
}

void TileInserter::plan(const TrainingSet& training, TilePlan& plan) const {
  PhaseClock clock;
  prepare_points(training, plan);
  plan.rejected_points = static_cast<std::size_t>(std::count(plan.bad.begin(), plan.bad.end(), 1));
  plan.phases.prepare = clock.lap();
  group_by_tile(training.size(), plan);
  // Scratch tiles are big, uneven units of work: the busiest go first so that the last ones
  // to finish are small (the order cannot change results, tiles are independent).
  plan.order.resize(plan.tiles.size());
  std::iota(plan.order.begin(), plan.order.end(), std::uint32_t{0});
  if (tile_shift_ != block_shift_) {
    std::stable_sort(plan.order.begin(), plan.order.end(), [&](std::uint32_t a, std::uint32_t b) {
      return plan.tile_offsets[a + 1] - plan.tile_offsets[a] >
             plan.tile_offsets[b + 1] - plan.tile_offsets[b];
    });
  }
  plan.phases.group = clock.lap();
}

}  // namespace semap::mapping::detail
