#pragma once

// Internal to semap_mapping: the per-thread scratch tile of the S-BKI insertion.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "semap/mapping/block_delta.hpp"
#include "semap/mapping/kernel.hpp"
#include "support_box.hpp"

namespace semap::mapping::detail {

// A cube of side^3 cells (side <= 32) of K classes where a tile's training points sum their
// kernel weights before they are added to the tile's blocks. Stored as K class planes, cell
// (z side + y) side + x of class c at c side^3 + cell, so the cells of a support row are
// contiguous: with AVX2 a hard-labelled point updates a row with one 8-float load, add and
// store into its label's plane (weights of 8 cells at once from KernelPolynomial, zero
// outside the sphere), where the blocks' cell-major layout would need 8 scattered floats K
// apart. A vector may run up to 7 floats past the row into the next row (or the planes'
// padding) adding +0.0 there, which leaves those cells unchanged. One bit mask per row of
// cells records the cells that got weight: they are the only non-zero ones; a second one per
// row records the classes that did (hard labels: a few of K), so that flush_block moves only
// those planes (adding the others' +0.0 would leave the delta unchanged).
class PlaneTile {
 public:
  PlaneTile(std::int32_t side, int num_classes);

  // Adds k(d) y to the cells of the tile-local `box` whose centres lie within ell of the
  // point, y one-hot in `label` (label >= 0) or the K floats at `y`. `d2[a][c]` is the squared
  // distance along axis a from the point to the centres of local cell box.lo[a] + c, readable
  // up to 8 floats past the box's width rounded up to 8 (values there are ignored).
  void add(const CellBox& box, const std::array<const float*, 3>& d2, std::int32_t label,
           const float* y, const KernelPolynomial& kernel);

  // Adds the n^3 cells starting at tile-local cell `first` to the zeroed `delta` (a block of n
  // cells per side), marks the cells that got weight there, and zeroes them here.
  void flush_block(const std::array<std::int32_t, 3>& first, BlockDelta& delta);

  // Clears the row masks once every block of the tile has been flushed.
  void clear_marks();

 private:
  std::int32_t side_;
  std::size_t k_;
  std::size_t plane_;  // floats per class plane
  std::vector<float> planes_;
  std::vector<std::uint32_t> rows_;
  std::vector<std::uint64_t> row_classes_;  // bit c: class c got weight in the row (K <= 64)
  // The rows of the point being added: index in the tile, dy^2 + dz^2, ell^2 - that.
  std::vector<std::uint32_t> job_rows_;
  std::vector<float> job_dyz2_;
  std::vector<float> job_rest_;
};

}  // namespace semap::mapping::detail
