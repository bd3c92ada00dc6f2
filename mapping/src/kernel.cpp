#include "semap/mapping/kernel.hpp"

#include <cmath>
#include <cstddef>
#include <numbers>
#include <stdexcept>

namespace semap::mapping {

SparseKernel::SparseKernel(float sf2, float ell) : sf2_(sf2), ell_(ell) {
  if (!(sf2 > 0.0f && ell > 0.0f)) throw std::invalid_argument("kernel needs sf2 > 0, ell > 0");
}

double SparseKernel::operator()(double distance) const {
  const double r = distance / ell_;
  if (r >= 1.0) return 0.0;
  const double a = 2.0 * std::numbers::pi * r;
  return sf2_ * ((2.0 + std::cos(a)) * (1.0 - r) / 3.0 + std::sin(a) / (2.0 * std::numbers::pi));
}

KernelPolynomial::KernelPolynomial(const SparseKernel& kernel)
    : ell2_(kernel.ell() * kernel.ell()),
      scale_(static_cast<float>(kPieces * kPieces) / ell2_),
      coefficients_{} {
  constexpr int n = kDegree + 1;
  using Poly = std::array<double, n>;
  // Chebyshev polynomials T_0..T_kDegree as monomial coefficients in u in [-1, 1].
  std::array<Poly, n> chebyshev{};
  chebyshev[0][0] = 1.0;
  chebyshev[1][1] = 1.0;
  for (std::size_t j = 2; j < n; ++j) {
    for (std::size_t p = 0; p < n; ++p) {
      chebyshev[j][p] = -chebyshev[j - 2][p] + (p > 0 ? 2.0 * chebyshev[j - 1][p - 1] : 0.0);
    }
  }
  const double pieces = kPieces;
  for (std::size_t piece = 0; piece < kPieces; ++piece) {
    // Piece `piece` covers r = (piece + t) / kPieces for t in [0, 1], u = 2 t - 1; it
    // interpolates g(r) = k(r) / (kPieces (1 - r))^5 at the Chebyshev nodes in u.
    Poly values{};
    for (std::size_t node = 0; node < n; ++node) {
      const double u = std::cos(std::numbers::pi * (static_cast<double>(node) + 0.5) / n);
      const double r = (static_cast<double>(piece) + 0.5 * (u + 1.0)) / pieces;
      values[node] = kernel(r * kernel.ell()) / std::pow(pieces * (1.0 - r), 5);
    }
    Poly in_u{};
    for (std::size_t j = 0; j < n; ++j) {
      double c = 0.0;
      for (std::size_t node = 0; node < n; ++node) {
        c += values[node] * std::cos(std::numbers::pi * static_cast<double>(j) *
                                     (static_cast<double>(node) + 0.5) / n);
      }
      c *= (j == 0 ? 1.0 : 2.0) / n;
      for (std::size_t p = 0; p < n; ++p) in_u[p] += c * chebyshev[j][p];
    }
    // The same polynomial in t: Horner's rule on polynomials, substituting u = 2 t - 1.
    Poly in_t{};
    for (std::size_t j = n; j-- > 0;) {
      Poly next{};
      for (std::size_t p = 0; p < n; ++p) {
        next[p] = -in_t[p] + (p > 0 ? 2.0 * in_t[p - 1] : 0.0);
      }
      next[0] += in_u[j];
      in_t = next;
    }
    for (std::size_t p = 0; p < n; ++p) coefficients_[p][piece] = static_cast<float>(in_t[p]);
  }
}

}  // namespace semap::mapping
