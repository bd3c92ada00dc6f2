#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>

namespace semap::mapping {

// A dense cube of cells_per_side^3 cells, the unit every map stores, pages, saves and sends.
// Per cell it holds `channels` floats of evidence, whose meaning is the cell model's (S-BKI /
// S-CSM: K Dirichlet increments alpha - alpha_0, so blocks from different maps can simply be
// added; log-odds: occupancy then K label log-odds), and one bit that says whether the cell was
// ever observed. Cell c = (z * n + y) * n + x holds evidence()[c * channels .. + channels).
//
// The evidence lives in storage owned by the EvidenceGrid (its BlockArena); a block only
// borrows it.
class Block {
 public:
  // `storage`: cells * channels zeroed floats, or nullptr for a block paged out of memory
  // (never read).
  Block(int cells_per_side, int channels, float* storage);

  int cells_per_side() const { return n_; }
  int num_cells() const { return n_ * n_ * n_; }
  int channels() const { return channels_; }
  int cell_of(int x, int y, int z) const { return (z * n_ + y) * n_ + x; }

  std::span<const float> evidence() const {
    return {storage_, static_cast<std::size_t>(num_cells()) * channels_};
  }
  std::span<const float> cell_evidence(int cell) const {
    return {storage_ + static_cast<std::size_t>(cell) * channels_,
            static_cast<std::size_t>(channels_)};
  }
  // Raw write access for the update loops; callers mark the cells they touch.
  float* cell_evidence_mutable(int cell) {
    return storage_ + static_cast<std::size_t>(cell) * channels_;
  }

  bool observed(int cell) const { return (observed_[cell >> 6] >> (cell & 63)) & 1u; }
  void mark_observed(int cell) { observed_[cell >> 6] |= std::uint64_t{1} << (cell & 63); }
  // Marks the cells of `mask` in the 64-cell word `word` (cells 64 word .. 64 word + 63).
  void mark_observed_word(int word, std::uint64_t mask) { observed_[word] |= mask; }
  int num_observed() const;
  // The observed bits, cell c at bit c % 64 of word c / 64.
  std::span<const std::uint64_t> observed_words() const;

  // Adds evidence (num_cells * channels floats) and sets the observed bits of `observed` (as
  // observed_words()): how a block written out by a checkpoint or a pager comes back exactly.
  void restore(std::span<const float> evidence, std::span<const std::uint64_t> observed);
  // Adds evidence for every cell; cells given any non-zero value become observed. This is how
  // maps are merged and files are read.
  void add_evidence(std::span<const float> evidence);
  // Replaces the evidence; cells with any non-zero value are observed, the others not.
  void assign(std::span<const float> evidence);

  // Bytes of this block (evidence, observed bits and the object itself).
  std::size_t bytes() const;

 private:
  void check_size(std::span<const float> evidence) const;

  int n_;
  int channels_;
  float* storage_;
  std::unique_ptr<std::uint64_t[]> observed_;
};

}  // namespace semap::mapping
