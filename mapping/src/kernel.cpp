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

KernelTable::KernelTable(const SparseKernel& kernel, int intervals) {
  if (intervals < 2) throw std::invalid_argument("kernel table needs at least 2 intervals");
  ell2_ = kernel.ell() * kernel.ell();
  const double step = static_cast<double>(ell2_) / intervals;
  inv_step_ = static_cast<float>(1.0 / step);
  last_ = static_cast<float>(intervals);
  std::vector<double> values(static_cast<std::size_t>(intervals) + 1);
  for (int i = 0; i <= intervals; ++i) {
    values[static_cast<std::size_t>(i)] = kernel(std::sqrt(i * step));
  }
  // sqrt rounding may leave the last sample a hair inside the support; it must be exactly 0.
  values.back() = 0.0;
  lines_.assign(2 * (static_cast<std::size_t>(intervals) + 1), 0.0f);
  for (int i = 0; i < intervals; ++i) {
    const auto u = static_cast<std::size_t>(i);
    const double slope = values[u + 1] - values[u];
    lines_[2 * u] = static_cast<float>(values[u] - slope * i);
    lines_[2 * u + 1] = static_cast<float>(slope);
  }
}

}  // namespace semap::mapping

namespace semap::mapping {

KernelPolynomial::KernelPolynomial(const SparseKernel& kernel)
    : ell2_(kernel.ell() * kernel.ell()), inv_ell2_(1.0f / ell2_), coefficients_{} {
  constexpr int n = kDegree + 1;
  // Chebyshev polynomials T_0..T_kDegree as monomial coefficients in u in [-1, 1].
  std::array<std::array<double, n>, n> chebyshev{};
  chebyshev[0][0] = 1.0;
  chebyshev[1][1] = 1.0;
  for (int j = 2; j < n; ++j) {
    for (int p = 0; p < n; ++p) {
      chebyshev[j][p] = -chebyshev[j - 2][p] + (p > 0 ? 2.0 * chebyshev[j - 1][p - 1] : 0.0);
    }
  }
  for (int piece = 0; piece < kPieces; ++piece) {
    // Piece `piece` covers r = (piece + 0.5 + t) / kPieces for t in [-0.5, 0.5]; u = 2 t.
    std::array<double, n> values{};
    for (int node = 0; node < n; ++node) {
      const double u = std::cos(std::numbers::pi * (node + 0.5) / n);
      const double r = (piece + 0.5 + 0.5 * u) / kPieces;
      values[static_cast<std::size_t>(node)] = kernel(r * kernel.ell()) / std::pow(1.0 - r, 5);
    }
    std::array<double, n> monomial{};
    for (int j = 0; j < n; ++j) {
      double c = 0.0;
      for (int node = 0; node < n; ++node) {
        c += values[static_cast<std::size_t>(node)] *
             std::cos(std::numbers::pi * j * (node + 0.5) / n);
      }
      c *= (j == 0 ? 1.0 : 2.0) / n;
      for (int p = 0; p < n; ++p) monomial[static_cast<std::size_t>(p)] += c * chebyshev[j][p];
    }
    // Powers of u = 2 t become powers of t.
    for (int p = 0; p < n; ++p) {
      coefficients_[static_cast<std::size_t>(p)][static_cast<std::size_t>(piece)] =
          static_cast<float>(monomial[static_cast<std::size_t>(p)] * std::ldexp(1.0, p));
    }
  }
}

}  // namespace semap::mapping
