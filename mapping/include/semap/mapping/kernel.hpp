#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace semap::mapping {

// The sparse kernel of Melkumyan and Ramos used by S-BKI:
//   k(d) = sf2 [ (2 + cos(2 pi d/l)) (1 - d/l) / 3 + sin(2 pi d/l) / (2 pi) ]  for d < l,
// and 0 beyond. k(0) = sf2, k(l) = 0, smooth at both ends.
class SparseKernel {
 public:
  SparseKernel(float sf2, float ell);

  // Exact value, evaluated in double precision.
  double operator()(double distance) const;

  float sf2() const { return sf2_; }
  float ell() const { return ell_; }

 private:
  float sf2_;
  float ell_;
};

// The kernel as the map's engine evaluates it, for every block size and 8 lanes at a time
// without table lookups (a lane's coefficients are picked with one register permute each,
// where a table needs a memory gather per lane). With r = d / ell, k has a zero of order 5 at r =
// 1, so k = (kPieces (1 - r))^5 g(r) with g smooth and positive; g is kPieces polynomials of degree
// kDegree, one per 1/kPieces of the support, each interpolating the exact g at Chebyshev
// nodes. Error below 1e-6 sf2 (unit-tested; about 5e-7 sf2 in float arithmetic, mostly
// rounding), and positive wherever d < ell, as the exact kernel is.
class KernelPolynomial {
 public:
  static constexpr int kPieces = 8;
  static constexpr int kDegree = 4;
  // Per power j of t, the coefficient of every piece.
  using Coefficients = std::array<std::array<float, kPieces>, kDegree + 1>;

  explicit KernelPolynomial(const SparseKernel& kernel);

  // k at squared distance d2, exactly 0 for d2 >= ell^2 (after rounding). With
  // y = kPieces r = sqrt(d2 scale()), piece i = floor(y) is evaluated by Horner's rule in
  // t = y - i and multiplied by (kPieces - y)^5; vector code must use the same operations to
  // get the same bits.
  float operator()(float d2) const {
    const float y = std::sqrt(d2 * scale_);
    if (!(y < static_cast<float>(kPieces))) return 0.0f;
    const auto piece = static_cast<std::int32_t>(y);
    const float t = y - static_cast<float>(piece);
    const auto i = static_cast<std::size_t>(piece);
    float g = coefficients_[kDegree][i];
    for (int j = kDegree - 1; j >= 0; --j) {
      g = g * t + coefficients_[static_cast<std::size_t>(j)][i];
    }
    const float e = static_cast<float>(kPieces) - y;
    const float e2 = e * e;
    return g * (e2 * e2 * e);
  }

  float ell_squared() const { return ell2_; }
  // kPieces^2 / ell^2: d2 scale() = y^2.
  float scale() const { return scale_; }
  const Coefficients& coefficients() const { return coefficients_; }

 private:
  float ell2_;
  float scale_;
  Coefficients coefficients_;
};

}  // namespace semap::mapping
