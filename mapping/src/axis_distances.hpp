#pragma once

// Internal to semap_mapping: squared distances from a point to a run of cell centres along
// one axis, shared by the tile plan and the scratch tiles.

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include <cstdint>

namespace semap::mapping::detail {

// d2[c - lo] = ((c + 1/2) res - p)^2 for the cells c = lo..hi along one axis (d2 holds a
// multiple of 8 floats past lo covering hi). With AVX2, 8 cells per step with the same
// operations in the same order as the scalar loop, so the same bits; cells past hi get
// distances too, which nothing reads as part of the support.
inline void axis_distances(std::int32_t lo, std::int32_t hi, float p, float resolution, float* d2) {
#if defined(__AVX2__)
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  for (std::int32_t c = lo; c <= hi; c += 8, d2 += 8) {
    const __m256 cell = _mm256_cvtepi32_ps(_mm256_add_epi32(_mm256_set1_epi32(c), lane));
    const __m256 d = _mm256_sub_ps(
        _mm256_mul_ps(_mm256_add_ps(cell, _mm256_set1_ps(0.5f)), _mm256_set1_ps(resolution)),
        _mm256_set1_ps(p));
    _mm256_storeu_ps(d2, _mm256_mul_ps(d, d));
  }
#else
  for (std::int32_t c = lo; c <= hi; ++c) {
    const float d = (static_cast<float>(c) + 0.5f) * resolution - p;
    d2[c - lo] = d * d;
  }
#endif
}

}  // namespace semap::mapping::detail
