#pragma once

// Internal to semap_mapping: KernelPolynomial eight lanes at a time.

#if defined(__AVX2__)
#include <immintrin.h>

#include "semap/mapping/kernel.hpp"

namespace semap::mapping::detail {

// The polynomial kernel's coefficients, one register per power (lane = piece).
struct KernelLanes {
  explicit KernelLanes(const KernelPolynomial& kernel) {
    for (std::size_t j = 0; j <= KernelPolynomial::kDegree; ++j) {
      c[j] = _mm256_loadu_ps(kernel.coefficients()[j].data());
    }
    scale = _mm256_set1_ps(kernel.scale());
  }
  static_assert(KernelPolynomial::kPieces == 8, "one piece per lane of a permute");
  __m256 c[KernelPolynomial::kDegree + 1];
  __m256 scale;
};

// KernelPolynomial::operator() for 8 squared distances, 0 in lanes outside `inside`. The same
// operations in the same order (no FMA), so the same bits as the scalar path. Lanes with
// y >= kPieces (rounding at the sphere's edge) get e = 0, hence k = 0, instead of a branch.
inline __m256 kernel8(__m256 d2, __m256 inside, const KernelLanes& kernel) {
  const __m256 y = _mm256_sqrt_ps(_mm256_mul_ps(d2, kernel.scale));
  const __m256i piece = _mm256_cvttps_epi32(y);
  const __m256 t = _mm256_sub_ps(y, _mm256_cvtepi32_ps(piece));
  __m256 g = _mm256_permutevar8x32_ps(kernel.c[KernelPolynomial::kDegree], piece);
  for (int j = KernelPolynomial::kDegree - 1; j >= 0; --j) {
    g = _mm256_add_ps(_mm256_mul_ps(g, t), _mm256_permutevar8x32_ps(kernel.c[j], piece));
  }
  const __m256 e =
      _mm256_max_ps(_mm256_sub_ps(_mm256_set1_ps(static_cast<float>(KernelPolynomial::kPieces)), y),
                    _mm256_setzero_ps());
  const __m256 e2 = _mm256_mul_ps(e, e);
  return _mm256_and_ps(_mm256_mul_ps(g, _mm256_mul_ps(_mm256_mul_ps(e2, e2), e)), inside);
}

}  // namespace semap::mapping::detail

#endif
