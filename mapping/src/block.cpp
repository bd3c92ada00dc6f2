#include "semap/mapping/block.hpp"

#include <algorithm>
#include <bit>
#include <stdexcept>
#include <string>

namespace semap::mapping {

namespace {

// Malloc bookkeeping per heap allocation, counted so bytes per cell is not flattering.
constexpr std::size_t kAllocOverhead = 16;

std::size_t words_for(int cells) { return (static_cast<std::size_t>(cells) + 63) / 64; }

template <typename T>
std::size_t heap_bytes(const std::vector<T>& v) {
  return v.capacity() == 0 ? 0 : v.capacity() * sizeof(T) + kAllocOverhead;
}

// Entries being rebuilt by Block::merge, reused by the thread for every block it merges.
struct Entries {
  std::vector<std::uint32_t> first;
  std::vector<std::uint16_t> channel;
  std::vector<float> value;
};

// Copies n values into `to`. A block's entries grow a little with most scans, so growth leaves
// a quarter of headroom instead of reallocating at every merge.
template <typename T>
void store(const std::vector<T>& from, std::size_t n, std::vector<T>& to) {
  if (to.capacity() < n) {
    std::vector<T> grown;
    grown.reserve(n + n / 4);
    to.swap(grown);
  }
  to.assign(from.begin(), from.begin() + static_cast<std::ptrdiff_t>(n));
}

}  // namespace

Block::Block(int cells_per_side, int channels)
    : n_(cells_per_side),
      channels_(channels),
      observed_(words_for(num_cells()), 0),
      rank_(observed_.size(), 0) {
  if (channels < 1 || channels > 65536) {
    throw std::invalid_argument("block of " + std::to_string(channels) +
                                " channels: must be in [1, 65536]");
  }
}

int Block::num_observed() const {
  int count = 0;
  for (const std::uint64_t word : observed_) count += std::popcount(word);
  return count;
}

std::uint32_t Block::rank(int cell) const {
  const auto word = static_cast<std::size_t>(cell >> 6);
  const std::uint64_t below = (std::uint64_t{1} << (cell & 63)) - 1;
  return rank_[word] + static_cast<std::uint32_t>(std::popcount(observed_[word] & below));
}

void Block::update_ranks() {
  std::uint32_t count = 0;
  for (std::size_t w = 0; w < observed_.size(); ++w) {
    rank_[w] = count;
    count += static_cast<std::uint32_t>(std::popcount(observed_[w]));
  }
}

void Block::read_cell(int cell, std::span<float> out) const {
  std::fill(out.begin(), out.end(), 0.0f);
  if (!observed(cell)) return;
  const std::uint32_t r = rank(cell);
  for (std::uint32_t e = first_[r]; e < first_[r + 1]; ++e) out[channel_[e]] = value_[e];
}

std::vector<float> Block::dense() const {
  std::vector<float> out(static_cast<std::size_t>(num_cells()) * channels_, 0.0f);
  std::uint32_t r = 0;
  for (std::size_t w = 0; w < observed_.size(); ++w) {
    for (std::uint64_t bits = observed_[w]; bits != 0; bits &= bits - 1, ++r) {
      const std::size_t c = w * 64 + static_cast<std::size_t>(std::countr_zero(bits));
      float* row = out.data() + c * static_cast<std::size_t>(channels_);
      for (std::uint32_t e = first_[r]; e < first_[r + 1]; ++e) row[channel_[e]] = value_[e];
    }
  }
  return out;
}

template <typename Row>
void Block::merge(std::span<const std::uint64_t> mask, const Row& row, std::uint64_t channels) {
  const bool every_channel = channels == BlockDelta::kAllChannels || channels_ > 64;
  std::size_t cells = 0;
  std::size_t added_cells = 0;
  for (std::size_t w = 0; w < observed_.size(); ++w) {
    cells += static_cast<std::size_t>(std::popcount(observed_[w] | mask[w]));
    added_cells += static_cast<std::size_t>(std::popcount(mask[w]));
  }
  const std::size_t per_cell = every_channel ? static_cast<std::size_t>(channels_)
                                             : static_cast<std::size_t>(std::popcount(channels));
  thread_local Entries out;
  out.first.resize(cells + 1);
  out.channel.resize(value_.size() + added_cells * per_cell);  // at most
  out.value.resize(out.channel.size());
  std::uint32_t n = 0;  // entries written
  std::size_t cell = 0;
  std::uint32_t r = 0;  // rank of the next old observed cell
  for (std::size_t w = 0; w < observed_.size(); ++w) {
    const std::uint64_t old = observed_[w];
    const std::uint64_t added = mask[w];
    for (std::uint64_t bits = old | added; bits != 0; bits &= bits - 1) {
      const int bit = std::countr_zero(bits);
      out.first[cell++] = n;
      std::uint32_t e = 0;
      std::uint32_t end = 0;
      if ((old >> bit) & 1u) {
        e = first_[r];
        end = first_[r + 1];
        ++r;
      }
      const auto keep = [&] {
        out.channel[n] = channel_[e];
        out.value[n++] = value_[e++];
      };
      if ((added >> bit) & 1u) {
        // Old entries and the row's non-zero channels, both in channel order.
        const float* values = row(static_cast<int>(w * 64) + bit);
        const auto add = [&](int k) {
          const float v = values[k];
          if (v == 0.0f) return;
          while (e < end && channel_[e] < k) keep();
          out.channel[n] = static_cast<std::uint16_t>(k);
          if (e < end && channel_[e] == k) {
            out.value[n++] = value_[e++] + v;
          } else {
            out.value[n++] = v;
          }
        };
        if (every_channel) {
          for (int k = 0; k < channels_; ++k) add(k);
        } else {
          for (std::uint64_t left = channels; left != 0; left &= left - 1) {
            add(std::countr_zero(left));
          }
        }
      }
      while (e < end) keep();
    }
    observed_[w] = old | added;
  }
  out.first[cell] = n;
  store(out.first, cells + 1, first_);
  store(out.channel, n, channel_);
  store(out.value, n, value_);
  update_ranks();
}

void Block::add(int cell, int channel, float value) {
  if (!observed(cell)) {
    // A new observed cell: no entries, inserted at its rank.
    const std::uint32_t r = rank(cell);
    if (first_.empty()) first_.push_back(0);
    first_.insert(first_.begin() + r, first_[r]);
    observed_[static_cast<std::size_t>(cell >> 6)] |= std::uint64_t{1} << (cell & 63);
    update_ranks();
  }
  if (value == 0.0f) return;
  const std::uint32_t r = rank(cell);
  const auto begin = channel_.begin() + first_[r];
  const auto end = channel_.begin() + first_[r + 1];
  const auto at = std::lower_bound(begin, end, static_cast<std::uint16_t>(channel));
  const auto e = at - channel_.begin();
  if (at != end && *at == channel) {
    value_[static_cast<std::size_t>(e)] += value;
    return;
  }
  channel_.insert(at, static_cast<std::uint16_t>(channel));
  value_.insert(value_.begin() + e, value);
  for (std::size_t later = r + 1; later < first_.size(); ++later) ++first_[later];
}

void Block::add(BlockDelta& delta) {
  const BlockDelta& d = delta;
  merge(
      d.marked(), [&](int c) { return d.cell(c); }, d.channels_added());
  delta.clear();
}

void Block::prefetch() const {
  constexpr std::size_t kLine = 64;
  const auto fetch = [](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const char*>(data);
    for (std::size_t b = 0; b < bytes; b += kLine) __builtin_prefetch(p + b);
  };
  fetch(observed_.data(), observed_.size() * sizeof(std::uint64_t));
  fetch(first_.data(), first_.size() * sizeof(std::uint32_t));
  fetch(channel_.data(), channel_.size() * sizeof(std::uint16_t));
  fetch(value_.data(), value_.size() * sizeof(float));
}

void Block::set_cell(int cell, std::span<const float> values) {
  if (values.size() != static_cast<std::size_t>(channels_)) {
    throw std::invalid_argument("cell of " + std::to_string(values.size()) +
                                " channels, block has " + std::to_string(channels_));
  }
  // Clear the cell's entries, then merge the new values into the now empty cell.
  if (observed(cell)) {
    const std::uint32_t r = rank(cell);
    const std::uint32_t count = first_[r + 1] - first_[r];
    channel_.erase(channel_.begin() + first_[r], channel_.begin() + first_[r + 1]);
    value_.erase(value_.begin() + first_[r], value_.begin() + first_[r + 1]);
    for (std::size_t later = r + 1; later < first_.size(); ++later) first_[later] -= count;
  }
  std::vector<std::uint64_t> mask(observed_.size(), 0);
  mask[static_cast<std::size_t>(cell >> 6)] = std::uint64_t{1} << (cell & 63);
  merge(
      mask, [&](int) { return values.data(); }, BlockDelta::kAllChannels);
}

void Block::check_size(std::span<const float> evidence) const {
  const std::size_t expected = static_cast<std::size_t>(num_cells()) * channels_;
  if (evidence.size() != expected) {
    throw std::invalid_argument("block evidence has " + std::to_string(evidence.size()) +
                                " floats, expected " + std::to_string(expected));
  }
}

void Block::restore(std::span<const float> evidence, std::span<const std::uint64_t> observed) {
  check_size(evidence);
  if (observed.size() != observed_.size()) {
    throw std::invalid_argument("block has " + std::to_string(observed.size()) +
                                " observed words, expected " + std::to_string(observed_.size()));
  }
  std::vector<std::uint64_t> mask(observed.begin(), observed.end());
  add_dense(evidence, mask);
}

void Block::add_evidence(std::span<const float> evidence) {
  check_size(evidence);
  std::vector<std::uint64_t> mask(observed_.size(), 0);
  add_dense(evidence, mask);
}

void Block::add_dense(std::span<const float> evidence, std::vector<std::uint64_t>& mask) {
  const auto row = [&](int c) { return evidence.data() + static_cast<std::size_t>(c) * channels_; };
  for (int c = 0; c < num_cells(); ++c) {
    const float* values = row(c);
    if (std::any_of(values, values + channels_, [](float v) { return v != 0.0f; })) {
      mask[static_cast<std::size_t>(c >> 6)] |= std::uint64_t{1} << (c & 63);
    }
  }
  merge(mask, row, BlockDelta::kAllChannels);
}

void Block::assign(std::span<const float> evidence) {
  check_size(evidence);
  std::fill(observed_.begin(), observed_.end(), 0);
  first_.clear();
  channel_.clear();
  value_.clear();
  add_evidence(evidence);
}

std::size_t Block::bytes() const {
  return sizeof(Block) + heap_bytes(observed_) + heap_bytes(rank_) + heap_bytes(first_) +
         heap_bytes(channel_) + heap_bytes(value_);
}

}  // namespace semap::mapping
