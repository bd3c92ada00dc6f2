#include "semap/mapping/block_delta.hpp"

#include <algorithm>
#include <bit>

namespace semap::mapping {

BlockDelta::BlockDelta(int cells_per_side, int channels)
    : n_(cells_per_side),
      channels_(channels),
      values_(static_cast<std::size_t>(num_cells()) * static_cast<std::size_t>(channels), 0.0f),
      marked_((static_cast<std::size_t>(num_cells()) + 63) / 64, 0) {}

void BlockDelta::clear() {
  for (std::size_t w = 0; w < marked_.size(); ++w) {
    for (std::uint64_t bits = marked_[w]; bits != 0; bits &= bits - 1) {
      const int c = static_cast<int>(w * 64) + std::countr_zero(bits);
      std::fill_n(cell(c), channels_, 0.0f);
    }
    marked_[w] = 0;
  }
  channels_added_ = 0;
}

}  // namespace semap::mapping
