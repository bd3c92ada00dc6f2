#include "tile_inserter.hpp"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <bit>

#include "axis_distances.hpp"
#include "kernel_lanes.hpp"
#include "phase_clock.hpp"

namespace semap::mapping::detail {

namespace {

// Scratch tiles are 32 cells per side when that fits in kScratchBytes (K <= 4), else 16: big
// enough that most supports fit in one (fewer pieces and split rows), small enough that the
// scratch stays in L2 (K = 4: 512 KiB; K = 20: 16^3 cells, 320 KiB). A toy scan then has
// 8..18 tiles, one often holding 40 % of the work, so tiles are processed busiest first
// (16-cell tiles balance better but cost more on one core: bench/RESULTS.md).
constexpr std::size_t kScratchBytes = 512 * 1024;
constexpr std::int32_t kDirectBlockShift = 3;

std::int32_t tile_shift_for(const MapParams& params) {
  const std::int32_t block_shift = params.block_depth - 1;
  // Blocks of 8+ cells per side are tiles themselves: a support rarely spans many of them,
  // and the scratch's write-back (n K floats per touched block row) would cost more than
  // it saves at large K. S-CSM touches one cell per point: nothing to gain from a scratch.
  if (block_shift >= kDirectBlockShift || params.method == MapMethod::kCsm) return block_shift;
  const std::size_t big = std::size_t{32 * 32 * 32} * sizeof(float) * params.num_classes;
  return big <= kScratchBytes ? 5 : 4;
}

// Squared distances stored per point and axis: at least the widest support, a multiple of 8
// so that axis_distances may write whole vectors. A support spans 2 ell / res cells plus the
// rounding of its two float end points (well under one cell together inside the mappable
// range), so it has at most floor(2 ell / res) + 2 cells. No more than that: the plan's
// distance rows are its largest array.
std::size_t distances_per_axis(const MapParams& params) {
  const auto widest = static_cast<std::size_t>(2.0f * params.ell / params.resolution) + 2;
  return (widest + 7) / 8 * 8;
}

// Floats per axis of a scratch-tile piece's distances: a piece is at most a tile (32 cells)
// wide, and PlaneTile reads at most 32 floats per axis (4 vectors of a row).
constexpr std::size_t kPieceStride = 32;

// Blocks per task when blocks are the tiles.
constexpr std::size_t kBlocksPerTask = 16;

// Cells of one point gathered before the kernel is evaluated for them 8 at a time: a LiDAR
// support row has 4 cells, so evaluating per row would leave half of each vector unused.
constexpr std::size_t kGatherCells = 256;

// w[i] = k(d2[i]) for i < count; d2 is readable up to count rounded up to 8.
inline void gathered_weights(const float* d2, std::size_t count, const KernelPolynomial& kernel,
                             float* w) {
#if defined(__AVX2__)
  const KernelLanes lanes(kernel);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  for (std::size_t i = 0; i < count; i += 8) {
    const __m256 inside = _mm256_castsi256_ps(
        _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<std::int32_t>(count - i)), lane));
    _mm256_storeu_ps(w + i, kernel8(_mm256_loadu_ps(d2 + i), inside, lanes));
  }
#else
  for (std::size_t i = 0; i < count; ++i) w[i] = kernel(d2[i]);
#endif
}

// Adds k(d) y_i to every cell of the block-local `box` whose centre lies within ell of point
// i and marks them observed. `d2[a][c]` is the squared distance along axis a to the centres
// of local cell box.lo[a] + c (readable 8 floats past the box). Hard labels touch one float
// per cell.
template <bool kSoft>
void smooth_point(BlockDelta& delta, std::int32_t side, const CellBox& box,
                  const std::array<const float*, 3>& d2, const TrainingSet& training, std::size_t i,
                  const KernelPolynomial& kernel) {
  const auto k = static_cast<std::size_t>(training.num_classes);
  const float ell2 = kernel.ell_squared();
  const float* y = kSoft ? training.probabilities.data() + i * k : nullptr;
  const std::size_t label = kSoft ? 0 : static_cast<std::size_t>(training.labels[i]);
  const std::int32_t width = box.hi[0] - box.lo[0] + 1;
  const float* dx2 = d2[0];
  float* const evidence = delta.cell(0);
  if constexpr (kSoft) {
    delta.mark_all_channels();
  } else {
    delta.mark_channel(static_cast<int>(label));
  }
  // Squared distances and evidence offsets of the gathered cells, then their weights.
  alignas(32) std::array<float, kGatherCells + 8> cell_d2;
  std::array<std::uint32_t, kGatherCells> cell_offset;
  alignas(32) std::array<float, kGatherCells + 8> w;
  std::size_t count = 0;
  const auto add_gathered = [&] {
    std::fill_n(cell_d2.begin() + static_cast<std::ptrdiff_t>(count), 8, 0.0f);
    gathered_weights(cell_d2.data(), count, kernel, w.data());
    for (std::size_t c = 0; c < count; ++c) {
      float* alpha = evidence + cell_offset[c];
      if constexpr (kSoft) {
        for (std::size_t j = 0; j < k; ++j) alpha[j] += w[c] * y[j];
      } else {
        alpha[label] += w[c];
      }
    }
    count = 0;
  };
  for (std::int32_t z = box.lo[2]; z <= box.hi[2]; ++z) {
    const float dz2 = d2[2][z - box.lo[2]];
    // Rows whose centre line passes within ell: again one run, found without branches. At
    // its ends rounding may leave dyz2 >= ell^2; those rows then have no inside cell.
    const std::uint32_t rows_inside = inside_mask(d2[1], box.hi[1] - box.lo[1] + 1, ell2 - dz2);
    if (rows_inside == 0) continue;
    const std::int32_t y_first = std::countr_zero(rows_inside);
    const std::int32_t y_last = 31 - std::countl_zero(rows_inside);
    const std::size_t first_row = static_cast<std::size_t>(z * side + box.lo[1]);
    for (std::int32_t yy = y_first; yy <= y_last; ++yy) {
      const float dyz2 = dz2 + d2[1][yy];
      // x is inside when d2x < ell^2 - dyz2; the inside cells are one run (d2x is convex).
      const std::uint32_t mask = inside_mask(dx2, width, ell2 - dyz2);
      if (mask == 0) continue;
      if (count + static_cast<std::size_t>(width) > kGatherCells) add_gathered();
      // A row of side <= 32 cells starts at a multiple of side, so it lies in one 64-bit word.
      const std::size_t row = (first_row + static_cast<std::size_t>(yy)) * side;
      const std::size_t row_first = row + static_cast<std::size_t>(box.lo[0]);
      for (std::uint32_t bits = mask; bits != 0; bits &= bits - 1) {
        const int x = std::countr_zero(bits);
        cell_d2[count] = dyz2 + dx2[x];
        cell_offset[count] =
            static_cast<std::uint32_t>((row_first + static_cast<std::size_t>(x)) * k);
        ++count;
      }
      delta.mark_word(static_cast<int>(row >> 6), std::uint64_t{mask << box.lo[0]} << (row & 63));
    }
  }
  add_gathered();
}

}  // namespace

TileInserter::TileInserter(const MapParams& params)
    : params_(params),
      polynomial_(SparseKernel(params.sf2, params.ell)),
      block_shift_(params.block_depth - 1),
      tile_shift_(tile_shift_for(params)),
      blocks_per_tile_side_(1 << (tile_shift_ - block_shift_)),
      mask_words_((static_cast<std::size_t>(blocks_per_tile_side_) * blocks_per_tile_side_ *
                       blocks_per_tile_side_ +
                   63) /
                  64),
      // Only one-block tiles read their axis distances from the plan; scratch tiles
      // compute each piece's (see process_tile).
      width_(params.method == MapMethod::kCsm || tile_shift_ != block_shift_
                 ? 0
                 : distances_per_axis(params)),
      scratch_(std::int32_t{1} << tile_shift_, params.num_classes),
      deltas_(std::int32_t{1} << block_shift_, params.num_classes) {}

void TileInserter::create_blocks(TilePlan& plan, const BlockAt& block_at, const BlockFind& find,
                                 TileInsertResult& result) const {
  const std::int32_t t_side = blocks_per_tile_side_;
  const std::int32_t per_tile = tile_shift_ - block_shift_;
  const std::size_t tiles = plan.tiles.size();
  plan.block_offsets.assign(tiles + 1, 0);
  for (std::size_t t = 0; t < tiles; ++t) {
    const std::uint64_t* mask = plan.block_masks.data() + t * mask_words_;
    std::uint32_t count = 0;
    for (std::size_t w = 0; w < mask_words_; ++w) count += std::popcount(mask[w]);
    plan.block_offsets[t + 1] = plan.block_offsets[t] + count;
  }
  plan.tile_blocks.resize(plan.block_offsets[tiles]);
  result.updated_blocks.resize(plan.block_offsets[tiles]);
  // The blocks the map holds are looked up in parallel (a LiDAR scan touches tens of
  // thousands, most of them there already); the missing ones are then created serially, in
  // the same order as one serial pass would.
  tbb::parallel_for(std::size_t{0}, tiles, [&](std::size_t t) {
    const std::uint64_t* mask = plan.block_masks.data() + t * mask_words_;
    std::uint32_t j = plan.block_offsets[t];
    for (std::size_t w = 0; w < mask_words_; ++w) {
      for (std::uint64_t bits = mask[w]; bits != 0; bits &= bits - 1, ++j) {
        const auto local = static_cast<std::int32_t>(w * 64) + std::countr_zero(bits);
        const common::BlockIndex index{(plan.tiles[t].x << per_tile) + local % t_side,
                                       (plan.tiles[t].y << per_tile) + (local / t_side) % t_side,
                                       (plan.tiles[t].z << per_tile) + local / (t_side * t_side)};
        plan.tile_blocks[j] = {static_cast<std::uint32_t>(local), find(index)};
        result.updated_blocks[j] = index;
      }
    }
  });
  for (std::size_t j = 0; j < plan.tile_blocks.size(); ++j) {
    if (plan.tile_blocks[j].block == nullptr) {
      plan.tile_blocks[j].block = &block_at(result.updated_blocks[j]);
    }
  }
}

inline Piece TileInserter::piece_of(const TilePlan& plan, std::size_t i,
                                    const std::array<std::int32_t, 3>& base) const {
  const std::int32_t side = 1 << tile_shift_;
  const CellBox& support = plan.boxes[i];
  Piece piece{};
  const float* first = plan.distances.data() + i * 3 * width_;
  for (int a = 0; a < 3; ++a) {
    piece.box.lo[a] = std::max(support.lo[a], base[a]) - base[a];
    piece.box.hi[a] = std::min(support.hi[a], base[a] + side - 1) - base[a];
    piece.d2[a] = first + a * width_ + (base[a] + piece.box.lo[a] - support.lo[a]);
  }
  return piece;
}

void TileInserter::scatter_in_place(const TilePlan& plan, BlockDelta& delta,
                                    const std::array<std::int32_t, 3>& base, std::size_t i,
                                    const TrainingSet& training) const {
  const std::int32_t side = 1 << tile_shift_;
  const auto k = static_cast<std::size_t>(params_.num_classes);
  if (params_.method == MapMethod::kCsm) {
    // The support is the point's cell, inside this block.
    const CellBox& cell_box = plan.boxes[i];
    const std::int32_t n = delta.cells_per_side();
    const int cell =
        ((cell_box.lo[2] - base[2]) * n + cell_box.lo[1] - base[1]) * n + cell_box.lo[0] - base[0];
    float* alpha = delta.cell(cell);
    if (training.labels[i] >= 0) {
      alpha[training.labels[i]] += 1.0f;
      delta.mark_channel(training.labels[i]);
    } else {
      const float* y = training.probabilities.data() + i * k;
      for (std::size_t c = 0; c < k; ++c) alpha[c] += y[c];
      delta.mark_all_channels();
    }
    delta.mark(cell);
    return;
  }
  const Piece piece = piece_of(plan, i, base);
  const CellBox& box = piece.box;
  if (training.labels[i] >= 0) {
    smooth_point<false>(delta, side, box, piece.d2, training, i, polynomial_);
  } else {
    smooth_point<true>(delta, side, box, piece.d2, training, i, polynomial_);
  }
}

void TileInserter::write_back(const TilePlan& plan, PlaneTile& scratch, std::size_t tile) {
  const std::int32_t n = 1 << block_shift_;
  const std::int32_t t_side = blocks_per_tile_side_;
  BlockDelta& delta = deltas_.local();
  const std::uint32_t end = plan.block_offsets[tile + 1];
  for (std::uint32_t j = plan.block_offsets[tile]; j < end; ++j) {
    if (j + 1 < end) plan.tile_blocks[j + 1].block->prefetch();
    const auto local = static_cast<std::int32_t>(plan.tile_blocks[j].local);
    scratch.flush_block(
        {(local % t_side) * n, ((local / t_side) % t_side) * n, (local / (t_side * t_side)) * n},
        delta);
    plan.tile_blocks[j].block->add(delta);
  }
  scratch.clear_marks();
}

void TileInserter::process_tile(const TilePlan& plan, std::size_t tile,
                                const TrainingSet& training) {
  const std::array<std::int32_t, 3> base{plan.tiles[tile].x << tile_shift_,
                                         plan.tiles[tile].y << tile_shift_,
                                         plan.tiles[tile].z << tile_shift_};
  if (tile_shift_ == block_shift_) {
    // The tile is one block: its points sum their weights in the block's delta.
    BlockDelta& delta = deltas_.local();
    for (std::uint32_t p = plan.tile_offsets[tile]; p < plan.tile_offsets[tile + 1]; ++p) {
      scatter_in_place(plan, delta, base, plan.tile_points[p], training);
    }
    plan.tile_blocks[plan.block_offsets[tile]].block->add(delta);
    return;
  }
  const auto k = static_cast<std::size_t>(params_.num_classes);
  const std::int32_t side = 1 << tile_shift_;
  const float resolution = params_.resolution;
  PlaneTile& scratch = scratch_.local();
  // A piece's squared axis distances, computed here (a few vector operations per axis) rather
  // than stored per point in the plan, whose largest array they would be. Same operations,
  // same bits.
  // Zeroed once so that reads past a piece's cells (ignored by PlaneTile) see defined values.
  std::array<float, 3 * kPieceStride> distances{};
  for (std::uint32_t p = plan.tile_offsets[tile]; p < plan.tile_offsets[tile + 1]; ++p) {
    const std::uint32_t i = plan.tile_points[p];
    const CellBox& support = plan.boxes[i];
    Piece piece{};
    for (int a = 0; a < 3; ++a) {
      piece.box.lo[a] = std::max(support.lo[a], base[a]) - base[a];
      piece.box.hi[a] = std::min(support.hi[a], base[a] + side - 1) - base[a];
      float* d2 = distances.data() + a * kPieceStride;
      axis_distances(base[a] + piece.box.lo[a], base[a] + piece.box.hi[a], training.points[i][a],
                     resolution, d2);
      piece.d2[a] = d2;
    }
    const std::int32_t label = training.labels[i];
    scratch.add(piece.box, piece.d2, label,
                label >= 0 ? nullptr : training.probabilities.data() + i * k, polynomial_);
  }
  write_back(plan, scratch, tile);
}

TileInsertResult TileInserter::insert(const TrainingSet& training, const BlockAt& block_at,
                                      const BlockFind& find) {
  plan(training, plan_);
  return apply(plan_, training, block_at, find);
}

TileInsertResult TileInserter::apply(TilePlan& plan, const TrainingSet& training,
                                     const BlockAt& block_at, const BlockFind& find) {
  TileInsertResult result;
  result.rejected_points = plan.rejected_points;
  result.phases = plan.phases;
  PhaseClock clock;
  // Creating blocks mutates the map's table, so it happens before the parallel part.
  create_blocks(plan, block_at, find, result);
  result.phases.blocks = clock.lap();
  // One-block tiles are small (S-CSM: a few points each) and go in groups of kBlocksPerTask
  // to keep the task overhead down.
  const bool in_place = tile_shift_ == block_shift_;
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, plan.tiles.size(), in_place ? kBlocksPerTask : 1),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t t = range.begin(); t != range.end(); ++t) {
          process_tile(plan, plan.order[t], training);
        }
      },
      tbb::simple_partitioner());
  result.phases.scatter = clock.lap();
  return result;
}

}  // namespace semap::mapping::detail
