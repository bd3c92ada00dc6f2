#include "semap/mapping/block.hpp"

#include <algorithm>
#include <bit>
#include <stdexcept>
#include <string>

namespace semap::mapping {

namespace {

std::size_t words_for(int cells) { return (static_cast<std::size_t>(cells) + 63) / 64; }

}  // namespace

Block::Block(int cells_per_side, int channels, float* storage)
    : n_(cells_per_side),
      channels_(channels),
      storage_(storage),
      observed_(new std::uint64_t[words_for(num_cells())]()) {}

int Block::num_observed() const {
  int count = 0;
  for (std::size_t w = 0; w < words_for(num_cells()); ++w) count += std::popcount(observed_[w]);
  return count;
}

std::span<const std::uint64_t> Block::observed_words() const {
  return {observed_.get(), words_for(num_cells())};
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
  if (observed.size() != words_for(num_cells())) {
    throw std::invalid_argument("block has " + std::to_string(observed.size()) +
                                " observed words, expected " +
                                std::to_string(words_for(num_cells())));
  }
  for (std::size_t i = 0; i < evidence.size(); ++i) storage_[i] += evidence[i];
  for (std::size_t w = 0; w < observed.size(); ++w) observed_[w] |= observed[w];
}

void Block::add_evidence(std::span<const float> evidence) {
  check_size(evidence);
  for (int c = 0; c < num_cells(); ++c) {
    float* dst = cell_evidence_mutable(c);
    const float* src = evidence.data() + static_cast<std::size_t>(c) * channels_;
    bool touched = false;
    for (int k = 0; k < channels_; ++k) {
      dst[k] += src[k];
      touched = touched || src[k] != 0.0f;
    }
    if (touched) mark_observed(c);
  }
}

void Block::assign(std::span<const float> evidence) {
  check_size(evidence);
  std::copy(evidence.begin(), evidence.end(), storage_);
  std::fill_n(observed_.get(), words_for(num_cells()), std::uint64_t{0});
  for (int c = 0; c < num_cells(); ++c) {
    const auto cell = cell_evidence(c);
    if (std::any_of(cell.begin(), cell.end(), [](float v) { return v != 0.0f; })) {
      mark_observed(c);
    }
  }
}

std::size_t Block::bytes() const {
  return sizeof(Block) + static_cast<std::size_t>(num_cells()) * channels_ * sizeof(float) +
         words_for(num_cells()) * sizeof(std::uint64_t);
}

}  // namespace semap::mapping
