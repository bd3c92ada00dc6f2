#pragma once

#include <vector>

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

// The same kernel tabulated over squared distance, so the scatter loop needs neither sqrt nor
// trigonometry. Linear interpolation over 4096 intervals of d^2 keeps the absolute error below
// 2e-5 * sf2 (checked by a unit test against SparseKernel).
class KernelTable {
 public:
  explicit KernelTable(const SparseKernel& kernel, int intervals = 4096);

  // k at squared distance d2; 0 for d2 >= ell^2.
  float operator()(float d2) const {
    const float x = d2 * inv_step_;
    if (x >= last_) return 0.0f;
    const int i = static_cast<int>(x);
    const float t = x - static_cast<float>(i);
    return values_[i] + t * (values_[i + 1] - values_[i]);
  }

  float ell_squared() const { return ell2_; }

 private:
  std::vector<float> values_;
  float inv_step_;
  float last_;
  float ell2_;
};

}  // namespace semap::mapping
