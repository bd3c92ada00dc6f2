#include "semap/mapping/block.hpp"

#include <bit>
#include <new>
#include <stdexcept>
#include <string>

namespace semap::mapping {

namespace {

std::size_t words_for(int cells) { return (static_cast<std::size_t>(cells) + 63) / 64; }

}  // namespace

Block::Block(int cells_per_side, int num_classes)
    : n_(cells_per_side),
      k_(num_classes),
      evidence_(static_cast<float*>(std::calloc(static_cast<std::size_t>(num_cells()) * num_classes,
                                                sizeof(float))),
                FreeDeleter{true}),
      observed_(new std::uint64_t[words_for(num_cells())]()) {
  if (!evidence_) throw std::bad_alloc();
}

Block::Block(int cells_per_side, int num_classes, float* storage)
    : n_(cells_per_side),
      k_(num_classes),
      evidence_(storage, FreeDeleter{false}),
      observed_(new std::uint64_t[words_for(num_cells())]()) {}

std::span<const float> Block::evidence() const {
  return {evidence_.get(), static_cast<std::size_t>(num_cells()) * k_};
}

int Block::num_observed() const {
  int count = 0;
  for (std::size_t w = 0; w < words_for(num_cells()); ++w) count += std::popcount(observed_[w]);
  return count;
}

std::span<const std::uint64_t> Block::observed_words() const {
  return {observed_.get(), words_for(num_cells())};
}

void Block::restore(std::span<const float> evidence, std::span<const std::uint64_t> observed) {
  if (observed.size() != words_for(num_cells())) {
    throw std::invalid_argument("block has " + std::to_string(observed.size()) +
                                " observed words, expected " +
                                std::to_string(words_for(num_cells())));
  }
  add_evidence(evidence);
  for (std::size_t w = 0; w < observed.size(); ++w) observed_[w] |= observed[w];
}

void Block::add_evidence(std::span<const float> evidence) {
  if (evidence.size() != static_cast<std::size_t>(num_cells()) * k_) {
    throw std::invalid_argument("block evidence has " + std::to_string(evidence.size()) +
                                " floats, expected " + std::to_string(num_cells() * k_));
  }
  for (int c = 0; c < num_cells(); ++c) {
    float* dst = cell_evidence_mutable(c);
    const float* src = evidence.data() + static_cast<std::size_t>(c) * k_;
    float sum = 0.0f;
    for (int k = 0; k < k_; ++k) {
      dst[k] += src[k];
      sum += src[k];
    }
    if (sum > 0.0f) mark_observed(c);
  }
}

std::size_t Block::bytes() const {
  return sizeof(Block) + static_cast<std::size_t>(num_cells()) * k_ * sizeof(float) +
         words_for(num_cells()) * sizeof(std::uint64_t);
}

}  // namespace semap::mapping
