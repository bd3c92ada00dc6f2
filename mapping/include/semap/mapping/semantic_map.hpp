#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "semap/common/cell_posterior.hpp"
#include "semap/common/map_grid.hpp"
#include "semap/common/messages.hpp"
#include "semap/mapping/block.hpp"
#include "semap/mapping/cell_reading.hpp"
#include "semap/mapping/evidence_grid.hpp"
#include "semap/mapping/kernel.hpp"
#include "semap/mapping/layered_map.hpp"
#include "semap/mapping/map_params.hpp"
#include "semap/mapping/training_data.hpp"

namespace semap::mapping {

namespace detail {
class TileInserter;
struct TilePlan;
}  // namespace detail

struct MapStats {
  std::size_t blocks = 0;          // blocks in memory
  std::size_t evicted_blocks = 0;  // blocks a pager moved out of memory (evict)
  std::size_t cells = 0;           // allocated cells (blocks * cells per block)
  std::size_t observed_cells = 0;  // cells that received evidence
  std::size_t bytes = 0;           // blocks plus the block table
  std::size_t scans = 0;
  std::size_t rejected_points = 0;  // bad input points, summed over scans
  double bytes_per_cell() const { return cells ? static_cast<double>(bytes) / cells : 0.0; }
};

// Wall time of one insert's steps, in seconds (steady clock; map_bench prints them).
struct InsertPhases {
  double training = 0;  // build_training_set (0 when given a prepared training set)
  double prepare = 0;   // per point: checks, support box, axis distances (parallel)
  double group = 0;     // (point, tile) pairs, tile numbering, counting sort, block masks
  double blocks = 0;    // creating missing blocks (serial: mutates the block table)
  double scatter = 0;   // kernel sums into the tiles and write-back (parallel over tiles)
};

// What one insert did.
struct InsertResult {
  std::size_t training_points = 0;
  std::size_t hits = 0;
  std::size_t rejected_points = 0;
  std::size_t out_of_range = 0;
  std::size_t blocks_updated = 0;
  std::vector<common::BlockIndex> updated_blocks;  // the blocks this insert wrote to
  InsertPhases phases;
};

// The continuous semantic map of Gan et al. (S-CSM / S-BKI): blocks of cells, each cell a
// Dirichlet posterior over K classes (common::CellPosterior) updated in place by every scan.
//
// The blocks are the robot's own evidence layer of a LayeredMap: saving, merging, checkpoints,
// paging, export and the DDS publisher read that layer where it is, without a copy. Reads here
// (query, for_each_block, stats) see the robot's own evidence; layers merged in from other
// robots are read fused through layers().
//
// Insertion runs in parallel over blocks with TBB (use a tbb::task_arena or
// tbb::global_control to bound threads). Every block is written by one task that visits its
// training points in a fixed order, so the result does not depend on the thread count.
class SemanticMap {
 public:
  // A map whose own scans go to the layer of `robot`.
  explicit SemanticMap(const MapParams& params, SourceId robot = 0);
  ~SemanticMap();
  SemanticMap(SemanticMap&&) noexcept;
  SemanticMap& operator=(SemanticMap&&) noexcept;

  const MapParams& params() const { return params_; }
  // The map as stored: this robot's layer and any merged in (what .smap files and merging use).
  const LayeredMap& layers() const { return layers_; }
  SourceId robot() const { return robot_; }
  // This robot's evidence.
  const EvidenceGrid& grid() const { return *grid_; }

  // Builds the scan's training set (see build_training_set) and fuses it.
  InsertResult insert(const common::LabeledCloud& cloud, const Eigen::Vector3f& origin);
  // Inserts clouds[i] seen from origins[i] in order, with the same map and results as calling
  // insert(clouds[i], origins[i]) one after the other, but builds the training sets of the
  // next scans (they do not depend on the map) while the current one is fused: a
  // tbb::parallel_pipeline whose parallel stage builds training sets and groups their points
  // into tiles, and whose serial, in-order stage creates blocks and fuses them. If a scan's build
  // throws, the scans before it are inserted and the exception is rethrown, as in the loop. Throws
  // std::invalid_argument when the spans differ in length.
  std::vector<InsertResult> insert(std::span<const common::LabeledCloud> clouds,
                                   std::span<const Eigen::Vector3f> origins);
  // Fuses a prepared training set: each point adds k(d) y to every cell centre within ell
  // (S-BKI) or y to the cell containing it (S-CSM); bki_update.hpp states the update, and
  // params().engine says which engine computes it.
  InsertResult insert(const TrainingSet& training);

  // The cell containing `point`; nullopt outside allocated blocks.
  std::optional<CellReading> query(const Eigen::Vector3f& point) const;
  // Class at `point`: the argmax, or -1 where the map is unknown.
  int label_at(const Eigen::Vector3f& point) const;

  // Calls f(const common::BlockIndex&, const Block&) for every block in memory.
  template <typename F>
  void for_each_block(F&& f) const {
    grid_->for_each_block(std::forward<F>(f));
  }
  // Calls f(const Eigen::Vector3f& centre, const common::CellPosterior&) for every observed cell.
  template <typename F>
  void for_each_cell(F&& f) const {
    std::vector<float> evidence(static_cast<std::size_t>(params_.num_classes));
    for_each_block([&](const common::BlockIndex& index, const Block& block) {
      for (int c = 0; c < block.num_cells(); ++c) {
        if (!block.observed(c)) continue;
        block.read_cell(c, evidence);
        f(cell_center(index, c), common::CellPosterior(evidence, params_.prior, true));
      }
    });
  }

  // The block at `index` if it is in memory.
  const Block* find_block(const common::BlockIndex& index) const {
    return grid_->find_block(index);
  }
  // Adds evidence (cells per block * K floats) to a block, creating it if needed (merging).
  // Throws std::invalid_argument for a block index beyond +-2^20 or a wrong float count.
  void add_evidence(const common::BlockIndex& index, std::span<const float> evidence) {
    grid_->add_block(index, evidence);
  }
  // Adds a block's evidence and observed bits as Block::restore does, creating it if needed:
  // a block coming back from a checkpoint or a pager. Throws as add_evidence.
  void restore_block(const common::BlockIndex& index, std::span<const float> evidence,
                     std::span<const std::uint64_t> observed) {
    grid_->restore_block(index, evidence, observed);
  }
  // Drops the block at `index` from memory (a pager has written it out). Returns false when it
  // is not in memory. An insert that reaches an evicted block starts it again from zero
  // evidence: restore it first.
  bool evict(const common::BlockIndex& index) { return grid_->evict(index); }

  common::BlockIndex block_of(const Eigen::Vector3f& point) const;
  Eigen::Vector3f cell_center(const common::BlockIndex& block, int cell) const;

  MapStats stats() const;
  // Inserts so far (cheap, unlike stats()): the update count of the robot's layer.
  std::size_t scans() const { return static_cast<std::size_t>(grid_->updates()); }

 private:
  // insert(training), with the map-independent part already done when `plan` is given.
  InsertResult fuse(const TrainingSet& training, detail::TilePlan* plan);
  // fuse() plus the training set's own rejected and out-of-range counts (scans given as clouds).
  InsertResult fuse_scan(const TrainingSet& training, detail::TilePlan* plan);

  MapParams params_;
  LayeredMap layers_;
  SourceId robot_;
  EvidenceGrid* grid_;  // the layer of robot_ in layers_ (std::map nodes do not move)
  std::size_t rejected_ = 0;
  // Insertion engine with its per-scan buffers and per-thread scratch, reused across scans.
  std::unique_ptr<detail::TileInserter> inserter_;
};

}  // namespace semap::mapping
