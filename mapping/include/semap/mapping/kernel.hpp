#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
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
// trigonometry. Piecewise linear over `intervals` equal steps of d^2; each step stores
// (offset, slope) so that k = offset[i] + slope[i] * s with s = d^2 / step, i = floor(s).
// 1024 intervals (8 KiB, stays in L1) keep the error below 1e-5 * sf2 (unit-tested).
class KernelTable {
 public:
  explicit KernelTable(const SparseKernel& kernel, int intervals = 1024);

  // k at squared distance d2; exactly 0 for d2 >= ell^2.
  float operator()(float d2) const { return view().clamped(d2); }

  float ell_squared() const { return ell2_; }

  // The table by value, for hot loops. inside() is operator() without the clamp, for d2
  // known to be below ell^2 up to rounding: there d2 / step stays below intervals + 1, whose
  // entry (0, 0) gives exactly 0.
  struct View {
    const float* lines;
    float inv_step;
    float last;
    float inside(float d2) const {
      const float s = d2 * inv_step;
      const auto i = static_cast<std::size_t>(static_cast<std::int32_t>(s));
      return lines[2 * i] + lines[2 * i + 1] * s;
    }
    // operator() of the table: 0 beyond ell.
    float clamped(float d2) const {
      const float s = std::min(d2 * inv_step, last);
      const auto i = static_cast<std::size_t>(static_cast<std::int32_t>(s));
      return lines[2 * i] + lines[2 * i + 1] * s;
    }
  };
  View view() const { return {lines_.data(), inv_step_, last_}; }

 private:
  // Interleaved (offset, slope) per step; the entry at s = intervals is (0, 0).
  std::vector<float> lines_;
  float inv_step_;
  float last_;
  float ell2_;
};

}  // namespace semap::mapping
