#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>

namespace semap::mapping {

// A dense cube of cells_per_side^3 cells. Per cell it stores K floats of Dirichlet evidence
// (alpha minus the prior, so blocks from different maps can simply be added) and one bit
// that says whether the cell was ever observed: covered by a training point's support (S-BKI:
// centre strictly within ell; S-CSM: the point lies in the cell) or given positive evidence. Cell c
// = (z * n + y) * n + x holds evidence()[c * K .. c * K + K).
class Block {
 public:
  Block(int cells_per_side, int num_classes);
  // Evidence in `storage` (cells * K zeroed floats), owned by the caller and outliving the
  // block (SemanticMap's BlockArena).
  Block(int cells_per_side, int num_classes, float* storage);

  int cells_per_side() const { return n_; }
  int num_cells() const { return n_ * n_ * n_; }
  int num_classes() const { return k_; }
  int cell_of(int x, int y, int z) const { return (z * n_ + y) * n_ + x; }

  std::span<const float> evidence() const;
  std::span<const float> cell_evidence(int cell) const {
    return {evidence_.get() + static_cast<std::size_t>(cell) * k_, static_cast<std::size_t>(k_)};
  }
  // Raw write access for the map's scatter loop; callers mark the cells they touch.
  float* cell_evidence_mutable(int cell) {
    return evidence_.get() + static_cast<std::size_t>(cell) * k_;
  }

  bool observed(int cell) const { return (observed_[cell >> 6] >> (cell & 63)) & 1u; }
  void mark_observed(int cell) { observed_[cell >> 6] |= std::uint64_t{1} << (cell & 63); }
  // Marks the cells of `mask` in the 64-cell word `word` (cells 64 word .. 64 word + 63).
  void mark_observed_word(int word, std::uint64_t mask) { observed_[word] |= mask; }
  int num_observed() const;
  // The observed bits, cell c at bit c % 64 of word c / 64.
  std::span<const std::uint64_t> observed_words() const;

  // Adds evidence (num_cells * K floats) and sets the observed bits of `observed` (as
  // observed_words()): how a block written out by a checkpoint or a pager comes back exactly.
  void restore(std::span<const float> evidence, std::span<const std::uint64_t> observed);

  // Adds evidence for every cell (num_cells * K floats); cells whose added evidence sums to
  // more than zero become observed. This is how maps are merged.
  void add_evidence(std::span<const float> evidence);

  // Bytes of this block (evidence, observed bits and the object itself).
  std::size_t bytes() const;

 private:
  // calloc'd: fresh pages arrive zeroed from the kernel, so a new block costs no memset and
  // its first touch happens in the (parallel) update rather than at creation.
  struct FreeDeleter {
    bool owned = true;
    void operator()(float* p) const {
      if (owned) std::free(p);
    }
  };

  int n_;
  int k_;
  std::unique_ptr<float[], FreeDeleter> evidence_;
  std::unique_ptr<std::uint64_t[]> observed_;
};

}  // namespace semap::mapping
