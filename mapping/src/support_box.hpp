#pragma once

// Internal to semap_mapping: the cells a training point's support covers.

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <array>
#include <cstdint>

namespace semap::mapping::detail {

// Inclusive range of cell coordinates per axis; empty when lo > hi.
struct CellBox {
  std::array<std::int32_t, 3> lo;
  std::array<std::int32_t, 3> hi;
};

// Bit x set when dx2[x] < rest, for x < width <= 32. With SSE2 and width <= 8 two compares of
// four lanes; reads 8 floats from dx2 either way in that case, so callers pad the array.
inline std::uint32_t inside_mask(const float* dx2, std::int32_t width, float rest) {
#if defined(__SSE2__)
  if (width <= 8) {
    const __m128 r = _mm_set1_ps(rest);
    const auto lo = static_cast<std::uint32_t>(_mm_movemask_ps(_mm_cmplt_ps(_mm_loadu_ps(dx2), r)));
    const auto hi =
        static_cast<std::uint32_t>(_mm_movemask_ps(_mm_cmplt_ps(_mm_loadu_ps(dx2 + 4), r)));
    return (lo | hi << 4) & ((std::uint32_t{1} << width) - 1);
  }
#endif
  std::uint32_t mask = 0;
  for (std::int32_t x = 0; x < width; ++x) {
    mask |= static_cast<std::uint32_t>(dx2[x] < rest) << x;
  }
  return mask;
}

}  // namespace semap::mapping::detail
