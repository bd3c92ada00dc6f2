#include "plane_tile.hpp"

#if defined(__AVX2__)
#include <immintrin.h>
#elif defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include <algorithm>
#include <bit>
#include <limits>

#include "kernel_lanes.hpp"

namespace semap::mapping::detail {

namespace {

// Floats a vector update may write past the last row of the last plane.
constexpr std::size_t kPad = 8;

// The planes as locals for the hot loop: stores through float* and std::uint32_t* would
// otherwise make the compiler reload PlaneTile's members after every row.
struct PlaneView {
  float* data;
  std::size_t plane;
  std::uint32_t* rows;
  std::uint64_t* row_classes;
  std::uint32_t* job_rows;  // a point's rows: index in the tile,
  float* job_dyz2;          // dy^2 + dz^2,
  float* job_rest;          // and ell^2 - dyz2
  std::size_t side;
  std::int32_t side_i;
  std::size_t k;
};

// PlaneTile::add for rows of at most 8 kChunks cells, labels hard or soft (`y`). First the
// rows whose centre line passes within ell are listed (compacted without branches), then
// each is updated in one loop: with a fixed trip count per point the loop exit is predicted,
// where per z-slice loops of varying length mispredicted about once per slice and made the
// long dependency chains of the kernel run one slice at a time. Per row, x is inside when
// d2x < ell^2 - dyz2; rounding may leave a listed row without inside cells, it then adds 0.
template <int kChunks, bool kSoft>
void add_rows(const PlaneView& planes, const CellBox& box, const std::array<const float*, 3>& d2,
              std::int32_t label, const float* y, const KernelPolynomial& kernel) {
  const float ell2 = kernel.ell_squared();
  const std::int32_t width = box.hi[0] - box.lo[0] + 1;
  const std::int32_t height = box.hi[1] - box.lo[1] + 1;
  const std::size_t side = planes.side;
  // A local: the stores below would otherwise make the compiler reload box.lo[0] per row.
  const auto shift = static_cast<std::uint32_t>(box.lo[0]);
  std::uint32_t* const rows = planes.job_rows;
  float* const dyz2s = planes.job_dyz2;
  float* const rests = planes.job_rest;
  std::size_t count = 0;
  for (std::int32_t z = box.lo[2]; z <= box.hi[2]; ++z) {
    const float dz2 = d2[2][z - box.lo[2]];
    const auto row = static_cast<std::uint32_t>(z * planes.side_i + box.lo[1]);
#if defined(__AVX2__)
    if (height <= 8) {
      // The listed rows are one run (dy^2 is convex): 8 entries from its first row on.
      const std::uint32_t inside = inside_mask(d2[1], height, ell2 - dz2);
      if (inside == 0) continue;
      const auto y_first = static_cast<std::uint32_t>(std::countr_zero(inside));
      const __m256 dyz2 = _mm256_add_ps(_mm256_set1_ps(dz2), _mm256_loadu_ps(d2[1] + y_first));
      _mm256_storeu_ps(dyz2s + count, dyz2);
      _mm256_storeu_ps(rests + count, _mm256_sub_ps(_mm256_set1_ps(ell2), dyz2));
      _mm256_storeu_si256(
          reinterpret_cast<__m256i*>(rows + count),
          _mm256_add_epi32(_mm256_set1_epi32(static_cast<std::int32_t>(row + y_first)),
                           _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)));
      count += static_cast<std::size_t>(std::popcount(inside));
      continue;
    }
#endif
    const float rest = ell2 - dz2;
    for (std::int32_t yy = 0; yy < height; ++yy) {
      rows[count] = row + static_cast<std::uint32_t>(yy);
      dyz2s[count] = dz2 + d2[1][yy];
      rests[count] = ell2 - dyz2s[count];
      count += d2[1][yy] < rest ? 1 : 0;
    }
  }
  // Hard labels write to their label's plane only. Soft ones may touch every class.
  const std::uint64_t classes =
      kSoft ? ~std::uint64_t{0} : std::uint64_t{1} << static_cast<std::uint32_t>(label & 63);
  float* const first = planes.data + static_cast<std::size_t>(box.lo[0]) +
                       (kSoft ? 0 : static_cast<std::size_t>(label) * planes.plane);
#if defined(__AVX2__)
  const KernelLanes lanes(kernel);
  // Per 8-cell chunk of the row the distances along x, +infinity in lanes beyond the box
  // so that they are never inside.
  __m256 dx[kChunks];
  for (int c = 0; c < kChunks; ++c) {
    const __m256 in_box = _mm256_castsi256_ps(_mm256_cmpgt_epi32(
        _mm256_set1_epi32(width - 8 * c), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)));
    dx[c] = _mm256_blendv_ps(_mm256_set1_ps(std::numeric_limits<float>::infinity()),
                             _mm256_loadu_ps(d2[0] + 8 * c), in_box);
  }
#endif
  for (std::size_t j = 0; j < count; ++j) {
    const std::size_t row = rows[j];
    float* cells = first + row * side;
    std::uint32_t mask = 0;
#if defined(__AVX2__)
    for (int c = 0; c < kChunks; ++c) {
      // Broadcasts from memory are loads, not shuffles competing with the kernel's permutes.
      const __m256 inside = _mm256_cmp_ps(dx[c], _mm256_broadcast_ss(rests + j), _CMP_LT_OQ);
      const auto bits = static_cast<std::uint32_t>(_mm256_movemask_ps(inside));
      // Wide rows skip their empty chunks; a single chunk is updated regardless (adding 0).
      if (kChunks > 1 && bits == 0) continue;
      mask |= bits << (8 * c);
      const __m256 w = kernel8(_mm256_add_ps(_mm256_broadcast_ss(dyz2s + j), dx[c]), inside, lanes);
      float* chunk = cells + 8 * c;
      if constexpr (kSoft) {
        for (std::size_t k = 0; k < planes.k; ++k) {
          float* p = chunk + k * planes.plane;
          _mm256_storeu_ps(
              p, _mm256_add_ps(_mm256_loadu_ps(p), _mm256_mul_ps(w, _mm256_set1_ps(y[k]))));
        }
      } else {
        _mm256_storeu_ps(chunk, _mm256_add_ps(_mm256_loadu_ps(chunk), w));
      }
    }
#else
    mask = inside_mask(d2[0], width, rests[j]);
    if (mask == 0) continue;
    const std::int32_t x_hi = 31 - std::countl_zero(mask);
    for (std::int32_t x = std::countr_zero(mask); x <= x_hi; ++x) {
      const float w = kernel(dyz2s[j] + d2[0][x]);
      if constexpr (kSoft) {
        for (std::size_t k = 0; k < planes.k; ++k) {
          cells[k * planes.plane + static_cast<std::size_t>(x)] += w * y[k];
        }
      } else {
        cells[x] += w;
      }
    }
#endif
    planes.rows[row] |= mask << shift;
    planes.row_classes[row] |= classes;
  }
}

}  // namespace

PlaneTile::PlaneTile(std::int32_t side, int num_classes)
    : side_(side),
      k_(static_cast<std::size_t>(num_classes)),
      plane_(static_cast<std::size_t>(side) * side * side),
      planes_(k_ * plane_ + kPad, 0.0f),
      rows_(static_cast<std::size_t>(side) * side, 0u),
      row_classes_(rows_.size(), 0u),
      // Rows of one point: at most side^2, and 8 listed at once.
      job_rows_(static_cast<std::size_t>(side) * side + 8),
      job_dyz2_(job_rows_.size()),
      job_rest_(job_rows_.size()) {}

void PlaneTile::add(const CellBox& box, const std::array<const float*, 3>& d2, std::int32_t label,
                    const float* y, const KernelPolynomial& kernel) {
  const PlaneView planes{planes_.data(),
                         plane_,
                         rows_.data(),
                         row_classes_.data(),
                         job_rows_.data(),
                         job_dyz2_.data(),
                         job_rest_.data(),
                         static_cast<std::size_t>(side_),
                         side_,
                         k_};
#if defined(__AVX2__)
  // Rows of up to 32 cells: 8 cells (the common case, ell <= 3.5 resolutions) or 4 vectors.
  constexpr int kWide = 4;
  if (box.hi[0] - box.lo[0] < 8) {
    if (label >= 0) return add_rows<1, false>(planes, box, d2, label, y, kernel);
    return add_rows<1, true>(planes, box, d2, label, y, kernel);
  }
  if (label >= 0) return add_rows<kWide, false>(planes, box, d2, label, y, kernel);
  return add_rows<kWide, true>(planes, box, d2, label, y, kernel);
#else
  if (label >= 0) return add_rows<1, false>(planes, box, d2, label, y, kernel);
  return add_rows<1, true>(planes, box, d2, label, y, kernel);
#endif
}

void PlaneTile::flush_block(const std::array<std::int32_t, 3>& first, BlockDelta& delta) {
  const std::int32_t n = delta.cells_per_side();
  const std::size_t k = k_;
  const std::size_t plane = plane_;
  const std::uint64_t low = (std::uint64_t{1} << n) - 1;
  for (std::int32_t z = 0; z < n; ++z) {
    for (std::int32_t y = 0; y < n; ++y) {
      const auto row = static_cast<std::size_t>((first[2] + z) * side_ + first[1] + y);
      const std::uint64_t bits = (std::uint64_t{rows_[row]} >> first[0]) & low;
      if (bits == 0) continue;
      // Only cells with a bit are non-zero, so adding and clearing the whole block row is
      // exact and leaves the scratch zeroed.
      float* src = planes_.data() + row * static_cast<std::size_t>(side_) +
                   static_cast<std::size_t>(first[0]);
      const int cell = (z * n + y) * n;
      float* dst = delta.cell(cell);
      delta.mark_word(cell >> 6, bits << (cell & 63));
      // Few classes (hard labels; K <= 64 so the mask covers them): those planes alone.
      const std::uint64_t classes = row_classes_[row];
      if (k <= 64 && static_cast<std::size_t>(std::popcount(classes)) * 4 <= k) {
        delta.mark_channels(classes);
        for (std::uint64_t left = classes; left != 0; left &= left - 1) {
          const auto c = static_cast<std::size_t>(std::countr_zero(left));
          float* p = src + c * plane;
          for (std::int32_t x = 0; x < n; ++x) {
            dst[static_cast<std::size_t>(x) * k + c] += p[x];
            p[x] = 0.0f;
          }
        }
        continue;
      }
      delta.mark_all_channels();
      std::size_t c = 0;
#if defined(__SSE2__)
      // Rows of 4 cells (blocks of depth 3): 4 classes at a time, a 4x4 transpose from
      // planes to cells.
      if (n == 4) {
        for (; c + 4 <= k; c += 4) {
          float* p = src + c * plane;
          __m128 r0 = _mm_loadu_ps(p);
          __m128 r1 = _mm_loadu_ps(p + plane);
          __m128 r2 = _mm_loadu_ps(p + 2 * plane);
          __m128 r3 = _mm_loadu_ps(p + 3 * plane);
          _MM_TRANSPOSE4_PS(r0, r1, r2, r3);
          float* d = dst + c;
          _mm_storeu_ps(d, _mm_add_ps(_mm_loadu_ps(d), r0));
          _mm_storeu_ps(d + k, _mm_add_ps(_mm_loadu_ps(d + k), r1));
          _mm_storeu_ps(d + 2 * k, _mm_add_ps(_mm_loadu_ps(d + 2 * k), r2));
          _mm_storeu_ps(d + 3 * k, _mm_add_ps(_mm_loadu_ps(d + 3 * k), r3));
          for (int j = 0; j < 4; ++j)
            _mm_storeu_ps(p + static_cast<std::size_t>(j) * plane, _mm_setzero_ps());
        }
      }
#endif
      for (; c < k; ++c) {
        float* p = src + c * plane;
        for (std::int32_t x = 0; x < n; ++x) {
          dst[static_cast<std::size_t>(x) * k + c] += p[x];
          p[x] = 0.0f;
        }
      }
    }
  }
}

void PlaneTile::clear_marks() {
  std::fill(rows_.begin(), rows_.end(), 0u);
  std::fill(row_classes_.begin(), row_classes_.end(), std::uint64_t{0});
}

}  // namespace semap::mapping::detail
