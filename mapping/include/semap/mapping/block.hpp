#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "semap/mapping/block_delta.hpp"

namespace semap::mapping {

// A cube of cells_per_side^3 cells, the unit every map stores, pages, saves and sends. Per cell
// it holds `channels` floats of evidence, whose meaning is the cell model's (S-BKI / S-CSM: K
// Dirichlet increments alpha - alpha_0 over the shared prior alpha_0, so blocks from different
// maps can simply be added; log-odds: occupancy then K label log-odds), and one bit that says
// whether the cell was ever observed. Cell c = (z * n + y) * n + x.
//
// Stored sparsely: most cells of a block are never observed, and an observed cell holds
// evidence for one to three of its K classes (a kernel reaches a cell from the few surfaces
// near it). Only the non-zero channels of observed cells are kept, as (channel, value) entries
// in cell order, channels ascending within a cell; every other channel reads as zero. The
// values are the floats a dense block would hold, so nothing is approximated.
class Block {
 public:
  // At most 65536 channels (the entries' channel field).
  Block(int cells_per_side, int channels);

  int cells_per_side() const { return n_; }
  int num_cells() const { return n_ * n_ * n_; }
  int channels() const { return channels_; }
  int cell_of(int x, int y, int z) const { return (z * n_ + y) * n_ + x; }

  bool observed(int cell) const { return (observed_[cell >> 6] >> (cell & 63)) & 1u; }
  int num_observed() const;
  // The observed bits, cell c at bit c % 64 of word c / 64.
  std::span<const std::uint64_t> observed_words() const { return observed_; }
  // Non-zero channels stored, over all cells.
  std::size_t num_entries() const { return value_.size(); }

  // The `channels` floats of `cell` (zeros where it holds nothing).
  void read_cell(int cell, std::span<float> out) const;
  // Every cell's channels, cell-major: num_cells * channels floats.
  std::vector<float> dense() const;

  // Adds `value` to one channel of `cell` and marks the cell observed: the plain update's
  // write, one entry at a time (the insertion engine merges whole BlockDeltas instead).
  void add(int cell, int channel, float value);
  // Adds the delta's marked cells, marks them observed and clears the delta.
  void add(BlockDelta& delta);
  // Asks the cache for the entries a merge reads: blocks lie scattered in memory, and fetching
  // the next while one is merged hides most of the misses that otherwise dominate merging.
  void prefetch() const;
  // Replaces the channels of `cell` and marks it observed.
  void set_cell(int cell, std::span<const float> values);

  // Adds dense evidence (num_cells * channels floats) and sets the observed bits of `observed`
  // (as observed_words()): how a block written out by a checkpoint or a pager comes back.
  void restore(std::span<const float> evidence, std::span<const std::uint64_t> observed);
  // Adds dense evidence for every cell; cells given any non-zero value become observed. This is
  // how maps are merged and files are read.
  void add_evidence(std::span<const float> evidence);
  // Replaces the evidence; cells with any non-zero value are observed, the others not.
  void assign(std::span<const float> evidence);

  // Heap and object bytes of this block, counting each allocation's bookkeeping.
  std::size_t bytes() const;

 private:
  void check_size(std::span<const float> evidence) const;
  // Adds dense evidence to the cells of `mask` and to every cell it gives a non-zero value.
  void add_dense(std::span<const float> evidence, std::vector<std::uint64_t>& mask);
  // Rank of an observed cell among the observed cells: its entries are first_[r] .. first_[r+1).
  std::uint32_t rank(int cell) const;
  // Rebuilds the entries with `row(c)` (channels floats) added to every cell marked in `mask`,
  // which become observed; only the channels of `channels` (BlockDelta::channels_added) are read.
  template <typename Row>
  void merge(std::span<const std::uint64_t> mask, const Row& row, std::uint64_t channels);
  void update_ranks();

  int n_;
  int channels_;
  std::vector<std::uint64_t> observed_;
  std::vector<std::uint32_t> rank_;     // per observed word: observed cells in the words before
  std::vector<std::uint32_t> first_;    // per observed cell, plus one: its first entry
  std::vector<std::uint16_t> channel_;  // per entry
  std::vector<float> value_;            // per entry
};

}  // namespace semap::mapping
