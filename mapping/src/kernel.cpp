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
  values_.resize(static_cast<std::size_t>(intervals) + 1);
  for (int i = 0; i <= intervals; ++i) {
    values_[static_cast<std::size_t>(i)] = static_cast<float>(kernel(std::sqrt(i * step)));
  }
}

}  // namespace semap::mapping
