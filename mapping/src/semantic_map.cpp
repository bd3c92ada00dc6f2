#include "semap/mapping/semantic_map.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "semap/mapping/voxel_hash_map.hpp"

namespace semap::mapping {

namespace {

// Inclusive range of global cell coordinates per axis; empty when lo > hi.
struct CellBox {
  std::array<std::int32_t, 3> lo;
  std::array<std::int32_t, 3> hi;
};

// Malloc bookkeeping per heap allocation, counted so bytes per cell is not flattering.
constexpr std::size_t kAllocOverhead = 16;

// std::floor/ceil are library calls without SSE4.1; these are exact for |x| < 2^31.
inline std::int32_t fast_floor(float x) {
  const auto i = static_cast<std::int32_t>(x);
  return i - static_cast<std::int32_t>(x < static_cast<float>(i));
}
inline std::int32_t fast_ceil(float x) {
  const auto i = static_cast<std::int32_t>(x);
  return i + static_cast<std::int32_t>(x > static_cast<float>(i));
}

// Training points are dropped when their cell coordinates could overflow the block keys.
bool mappable(const Eigen::Vector3f& p, float inv_res) {
  constexpr float kLimit = static_cast<float>(1 << 20) - 64.0f;
  return p.allFinite() && (p.cwiseAbs() * inv_res).maxCoeff() < kLimit;
}

// Cells a training point touches: for S-BKI all cells whose centre lies within ell per
// axis (rows are trimmed to the sphere later), for S-CSM the cell containing the point.
CellBox support_of(const Eigen::Vector3f& p, const MapParams& params) {
  const float inv_res = 1.0f / params.resolution;
  CellBox box{};
  for (int a = 0; a < 3; ++a) {
    if (params.method == Method::kCsm) {
      box.lo[a] = box.hi[a] = fast_floor(p[a] * inv_res);
    } else {
      box.lo[a] = fast_ceil((p[a] - params.ell) * inv_res - 0.5f);
      box.hi[a] = fast_floor((p[a] + params.ell) * inv_res - 0.5f);
    }
  }
  return box;
}

bool empty(const CellBox& box) {
  return box.lo[0] > box.hi[0] || box.lo[1] > box.hi[1] || box.lo[2] > box.hi[2];
}

// Training point indices grouped by the blocks their support overlaps; points of a block
// are in ascending order, which fixes the summation order of every cell.
struct BlockGroups {
  std::vector<BlockIndex> blocks;
  std::vector<std::uint32_t> offsets;  // blocks.size() + 1
  std::vector<std::uint32_t> points;
  std::vector<CellBox> boxes;  // support of every training point (empty if unusable)
  // S-BKI: squared distances from each point to the cell centres of its support box along
  // x, then y, then z (box widths), starting at distance_offsets[i]; computed once per point
  // instead of once per (point, block).
  std::vector<float> distances;
  std::vector<std::uint32_t> distance_offsets;
};

BlockGroups group_by_block(const TrainingSet& training, const std::vector<std::uint8_t>& usable,
                           const MapParams& params) {
  const std::int32_t shift = params.block_depth - 1;  // n = 2^shift cells per side
  VoxelHashMap ids(training.size() / 4 + 16);
  BlockGroups groups;
  groups.boxes.resize(training.size(), CellBox{{0, 0, 0}, {-1, -1, -1}});
  if (params.method != Method::kCsm) {
    groups.distance_offsets.assign(training.size(), 0);
    const auto width = static_cast<std::size_t>(2.0f * params.ell / params.resolution) + 2;
    groups.distances.reserve(training.size() * 3 * width);
  }
  std::vector<std::uint32_t> counts;
  // (block id, point index) pairs in point order.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  pairs.reserve(training.size() * (params.method == Method::kCsm ? 1 : 16));
  // Direct-mapped cache of block ids by the low two bits of each block coordinate: a point's
  // support spans at most 3 blocks per axis and neighbouring points share blocks, so most
  // lookups skip the hash table. Ids come from the table either way, so results are unchanged.
  struct CacheEntry {
    BlockIndex block{0, 0, 0};
    std::uint32_t id = VoxelHashMap::kNone;
  };
  std::array<CacheEntry, 64> cache{};
  const auto block_id = [&](const BlockIndex& b) {
    CacheEntry& e =
        cache[static_cast<std::size_t>((b.x & 3) | ((b.y & 3) << 2) | ((b.z & 3) << 4))];
    if (e.id != VoxelHashMap::kNone && e.block == b) return e.id;
    e.block = b;
    e.id = ids.insert(b);
    return e.id;
  };
  for (std::size_t i = 0; i < training.size(); ++i) {
    if (!usable[i]) continue;
    const CellBox box = support_of(training.points[i], params);
    groups.boxes[i] = box;
    if (empty(box)) continue;
    if (params.method != Method::kCsm) {
      groups.distance_offsets[i] = static_cast<std::uint32_t>(groups.distances.size());
      for (int a = 0; a < 3; ++a) {
        for (std::int32_t c = box.lo[a]; c <= box.hi[a]; ++c) {
          const float d =
              (static_cast<float>(c) + 0.5f) * params.resolution - training.points[i][a];
          groups.distances.push_back(d * d);
        }
      }
    }
    // n is a power of two, so an arithmetic shift is floor division.
    std::array<std::int32_t, 3> blo{}, bhi{};
    for (int a = 0; a < 3; ++a) {
      blo[a] = box.lo[a] >> shift;
      bhi[a] = box.hi[a] >> shift;
    }
    for (std::int32_t bz = blo[2]; bz <= bhi[2]; ++bz) {
      for (std::int32_t by = blo[1]; by <= bhi[1]; ++by) {
        for (std::int32_t bx = blo[0]; bx <= bhi[0]; ++bx) {
          const BlockIndex b{bx, by, bz};
          const std::uint32_t id = block_id(b);
          if (id == groups.blocks.size()) {
            groups.blocks.push_back(b);
            counts.push_back(0);
          }
          ++counts[id];
          pairs.emplace_back(id, static_cast<std::uint32_t>(i));
        }
      }
    }
  }
  groups.offsets.assign(groups.blocks.size() + 1, 0);
  for (std::size_t b = 0; b < counts.size(); ++b) {
    groups.offsets[b + 1] = groups.offsets[b] + counts[b];
  }
  std::vector<std::uint32_t> fill(groups.offsets.begin(), groups.offsets.end() - 1);
  groups.points.resize(pairs.size());
  for (const auto& [id, i] : pairs) groups.points[fill[id]++] = i;
  return groups;
}

// Adds 1 * y_i to the cell containing training point i (S-CSM).
void count_point(Block& block, int cell, const TrainingSet& training, std::size_t i) {
  const std::size_t k = static_cast<std::size_t>(training.num_classes);
  float* alpha = block.cell_evidence_mutable(cell);
  if (training.labels[i] >= 0) {
    alpha[training.labels[i]] += 1.0f;
  } else {
    const float* y = training.probabilities.data() + i * k;
    for (std::size_t c = 0; c < k; ++c) alpha[c] += y[c];
  }
  block.mark_observed(cell);
}

// Adds k(d) y_i to every cell of `box` (block-local, inclusive) within ell of point i.
// `d2[a][c - box.lo[a]]` is the squared distance along axis a to the centres of local cell c.
// Hard labels touch one float per cell, hence the separate instantiation.
template <bool kSoft>
void smooth_point(Block& block, const CellBox& box, const std::array<const float*, 3>& d2,
                  const TrainingSet& training, std::size_t i, const KernelTable& kernel) {
  const std::size_t k = static_cast<std::size_t>(training.num_classes);
  const float ell2 = kernel.ell_squared();
  const float* y = kSoft ? training.probabilities.data() + i * k : nullptr;
  // For a hard label only column `label` of the cell-major evidence array changes.
  float* column = block.cell_evidence_mutable(0) + (kSoft ? 0 : training.labels[i]);
  for (std::int32_t z = box.lo[2]; z <= box.hi[2]; ++z) {
    for (std::int32_t yy = box.lo[1]; yy <= box.hi[1]; ++yy) {
      const float dyz2 = d2[2][z - box.lo[2]] + d2[1][yy - box.lo[1]];
      if (dyz2 >= ell2) continue;
      // A row of n <= 32 cells starts at a multiple of n, so it lies in one 64-bit word.
      const int row = block.cell_of(0, yy, z);
      // Trim the row to the sphere; distances along x are convex, so both ends suffice.
      const float rest = ell2 - dyz2;
      std::int32_t x_lo = box.lo[0], x_hi = box.hi[0];
      while (x_lo <= x_hi && d2[0][x_lo - box.lo[0]] >= rest) ++x_lo;
      while (x_hi >= x_lo && d2[0][x_hi - box.lo[0]] >= rest) --x_hi;
      if (x_lo > x_hi) continue;
      for (std::int32_t x = x_lo; x <= x_hi; ++x) {
        const float w = kernel.inside(dyz2 + d2[0][x - box.lo[0]]);
        float* alpha = column + static_cast<std::size_t>(row + x) * k;
        if constexpr (kSoft) {
          for (std::size_t c = 0; c < k; ++c) alpha[c] += w * y[c];
        } else {
          *alpha += w;
        }
      }
      // Every cell centre strictly inside the support counts as observed.
      const std::uint64_t run = (std::uint64_t{2} << (x_hi - x_lo)) - 1;
      block.mark_observed_word(row >> 6, run << ((row + x_lo) & 63));
    }
  }
}

void update_block(Block& block, const BlockIndex& index, std::span<const std::uint32_t> points,
                  const TrainingSet& training, const BlockGroups& groups, const MapParams& params,
                  const KernelTable& kernel) {
  const std::int32_t n = params.cells_per_side();
  const std::array<std::int32_t, 3> base{index.x * n, index.y * n, index.z * n};
  for (const std::uint32_t i : points) {
    const CellBox& support = groups.boxes[i];
    CellBox box = support;
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = std::max(box.lo[a], base[a]) - base[a];
      box.hi[a] = std::min(box.hi[a], base[a] + n - 1) - base[a];
    }
    if (params.method == Method::kCsm) {
      count_point(block, block.cell_of(box.lo[0], box.lo[1], box.lo[2]), training, i);
      continue;
    }
    const float* first = groups.distances.data() + groups.distance_offsets[i];
    std::array<const float*, 3> d2{};
    for (int a = 0; a < 3; ++a) {
      d2[a] = first + (base[a] + box.lo[a] - support.lo[a]);
      first += support.hi[a] - support.lo[a] + 1;
    }
    if (training.labels[i] >= 0) {
      smooth_point<false>(block, box, d2, training, i, kernel);
    } else {
      smooth_point<true>(block, box, d2, training, i, kernel);
    }
  }
}

}  // namespace

SemanticMap::SemanticMap(const MapParams& params)
    : params_(params), kernel_((params.validate(), SparseKernel(params.sf2, params.ell))) {}

InsertResult SemanticMap::insert(const common::LabeledCloud& cloud, const Eigen::Vector3f& origin) {
  const TrainingSet training = build_training_set(cloud, origin, params_);
  InsertResult result = insert(training);
  result.rejected_points += training.rejected;
  result.out_of_range = training.out_of_range;
  rejected_ += training.rejected;
  return result;
}

InsertResult SemanticMap::insert(const TrainingSet& training) {
  if (training.num_classes != params_.num_classes) {
    throw std::invalid_argument("training set has " + std::to_string(training.num_classes) +
                                " classes, map has " + std::to_string(params_.num_classes));
  }
  InsertResult result;
  result.training_points = training.size();
  result.hits = training.num_hits;
  const float inv_res = 1.0f / params_.resolution;
  std::vector<std::uint8_t> usable(training.size(), 1);
  const std::size_t soft_rows = training.probabilities.size() / params_.num_classes;
  for (std::size_t i = 0; i < training.size(); ++i) {
    const std::int32_t label = training.labels[i];
    const bool label_ok = label >= 0 ? label < params_.num_classes : i < soft_rows;
    if (!label_ok || !mappable(training.points[i], inv_res)) {
      usable[i] = 0;
      ++result.rejected_points;
    }
  }
  rejected_ += result.rejected_points;

  const BlockGroups groups = group_by_block(training, usable, params_);
  // Creating blocks mutates the table, so it happens before the parallel part.
  std::vector<Block*> targets(groups.blocks.size());
  for (std::size_t b = 0; b < groups.blocks.size(); ++b) targets[b] = &block_at(groups.blocks[b]);

  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, groups.blocks.size()),
      [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t b = range.begin(); b != range.end(); ++b) {
          const std::span<const std::uint32_t> points(groups.points.data() + groups.offsets[b],
                                                      groups.offsets[b + 1] - groups.offsets[b]);
          update_block(*targets[b], groups.blocks[b], points, training, groups, params_, kernel_);
        }
      });
  result.blocks_updated = groups.blocks.size();
  result.updated_blocks = groups.blocks;
  ++scans_;
  return result;
}

BlockIndex SemanticMap::block_of(const Eigen::Vector3f& point) const {
  // Through the cell index, exactly as insert() and query() do, so boundaries agree.
  const float inv_res = 1.0f / params_.resolution;
  const std::int32_t n = params_.cells_per_side();
  return {floor_div(fast_floor(point.x() * inv_res), n),
          floor_div(fast_floor(point.y() * inv_res), n),
          floor_div(fast_floor(point.z() * inv_res), n)};
}

Eigen::Vector3f SemanticMap::cell_center(const BlockIndex& block, int cell) const {
  const int n = params_.cells_per_side();
  const Eigen::Vector3f local(static_cast<float>(cell % n), static_cast<float>((cell / n) % n),
                              static_cast<float>(cell / (n * n)));
  const Eigen::Vector3f first(static_cast<float>(block.x * n), static_cast<float>(block.y * n),
                              static_cast<float>(block.z * n));
  return (first + local + Eigen::Vector3f::Constant(0.5f)) * params_.resolution;
}

std::optional<CellPosterior> SemanticMap::query(const Eigen::Vector3f& point) const {
  const float inv_res = 1.0f / params_.resolution;
  if (!mappable(point, inv_res)) return std::nullopt;
  const std::int32_t n = params_.cells_per_side();
  const std::array<std::int32_t, 3> cell{
      static_cast<std::int32_t>(std::floor(point.x() * inv_res)),
      static_cast<std::int32_t>(std::floor(point.y() * inv_res)),
      static_cast<std::int32_t>(std::floor(point.z() * inv_res))};
  const BlockIndex index{floor_div(cell[0], n), floor_div(cell[1], n), floor_div(cell[2], n)};
  const Block* block = find_block(index);
  if (block == nullptr) return std::nullopt;
  const int c = block->cell_of(cell[0] - index.x * n, cell[1] - index.y * n, cell[2] - index.z * n);
  return CellPosterior(block->cell_evidence(c), params_.prior, block->observed(c));
}

int SemanticMap::label_at(const Eigen::Vector3f& point) const {
  const auto cell = query(point);
  return cell ? cell->label(params_.unknown_variance) : -1;
}

const Block* SemanticMap::find_block(const BlockIndex& index) const {
  if (!VoxelHashMap::in_range(index)) return nullptr;
  const std::uint32_t id = table_.find(index);
  return id == VoxelHashMap::kNone ? nullptr : &blocks_[id];
}

Block& SemanticMap::block_at(const BlockIndex& index) {
  const std::uint32_t id = table_.insert(index);
  if (id == blocks_.size()) {
    indices_.push_back(index);
    blocks_.emplace_back(params_.cells_per_side(), params_.num_classes);
  }
  return blocks_[id];
}

void SemanticMap::add_evidence(const BlockIndex& index, std::span<const float> evidence) {
  if (!VoxelHashMap::in_range(index)) {
    throw std::invalid_argument("block index beyond the map's +-2^20 range");
  }
  const std::size_t expected =
      static_cast<std::size_t>(params_.cells_per_block()) * params_.num_classes;
  if (evidence.size() != expected) {
    throw std::invalid_argument("block evidence has " + std::to_string(evidence.size()) +
                                " floats, expected " + std::to_string(expected));
  }
  block_at(index).add_evidence(evidence);
}

MapStats SemanticMap::stats() const {
  MapStats s;
  s.blocks = blocks_.size();
  s.scans = scans_;
  s.rejected_points = rejected_;
  // Table, index list and the deque's slots, then every block with its two heap arrays.
  s.bytes =
      table_.bytes() + indices_.capacity() * sizeof(BlockIndex) + blocks_.size() * sizeof(Block);
  for (const Block& block : blocks_) {
    s.cells += static_cast<std::size_t>(block.num_cells());
    s.observed_cells += static_cast<std::size_t>(block.num_observed());
    s.bytes += block.bytes() - sizeof(Block) + 2 * kAllocOverhead;
  }
  return s;
}

}  // namespace semap::mapping
