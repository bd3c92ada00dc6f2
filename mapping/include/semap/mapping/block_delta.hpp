#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace semap::mapping {

// Evidence on its way into one Block: a dense cell-major scratch of the block's cells (K floats
// per cell, zero where nothing is added) and a bit per cell that got any. The insertion
// engine's kernel loops add into it as they would into a dense block, then Block::add merges
// it into the block's sparse cells and clear() zeroes what was written. One per thread,
// reused for every block it writes.
class BlockDelta {
 public:
  BlockDelta(int cells_per_side, int channels);

  int cells_per_side() const { return n_; }
  int num_cells() const { return n_ * n_ * n_; }
  int channels() const { return channels_; }

  // The K floats of `cell`, to add into; mark the cell too.
  float* cell(int cell) { return values_.data() + static_cast<std::size_t>(cell) * channels_; }
  const float* cell(int cell) const {
    return values_.data() + static_cast<std::size_t>(cell) * channels_;
  }
  void mark(int cell) { marked_[cell >> 6] |= std::uint64_t{1} << (cell & 63); }
  // Marks the cells of `mask` in the 64-cell word `word`.
  void mark_word(int word, std::uint64_t mask) { marked_[word] |= mask; }
  // The marked cells, cell c at bit c % 64 of word c / 64.
  std::span<const std::uint64_t> marked() const { return marked_; }

  // Says which channels may have been added to (hard labels: a few of K), so that the merge
  // looks at those alone; channels beyond 63 count as all.
  void mark_channel(int channel) {
    channels_added_ |= channel < 64 ? std::uint64_t{1} << channel : kAllChannels;
  }
  void mark_channels(std::uint64_t channels) { channels_added_ |= channels; }
  void mark_all_channels() { channels_added_ = kAllChannels; }
  // Bit k: channel k may be non-zero; all bits set: any channel may be.
  std::uint64_t channels_added() const { return channels_added_; }
  static constexpr std::uint64_t kAllChannels = ~std::uint64_t{0};

  // Zeroes the marked cells and clears the marks.
  void clear();

 private:
  int n_;
  int channels_;
  std::vector<float> values_;
  std::vector<std::uint64_t> marked_;
  std::uint64_t channels_added_ = 0;
};

}  // namespace semap::mapping
