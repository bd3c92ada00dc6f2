#include "semap/mapping/kernel.hpp"

#include <cmath>
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
