#include "semap/common/latency_window.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace semap::common {

LatencyWindow::LatencyWindow(std::size_t capacity) : capacity_(capacity) {
  if (capacity_ == 0) throw std::invalid_argument("LatencyWindow: capacity must be > 0");
  ms_.reserve(capacity_);
}

void LatencyWindow::record(double seconds) {
  const auto ms = static_cast<float>(seconds * 1e3);
  std::lock_guard lock(mutex_);
  if (ms_.size() < capacity_) {
    ms_.push_back(ms);
  } else {
    ms_[next_] = ms;
    next_ = (next_ + 1) % capacity_;
  }
}

LatencyPercentiles LatencyWindow::percentiles() const {
  std::vector<float> v;
  {
    std::lock_guard lock(mutex_);
    v = ms_;
  }
  LatencyPercentiles p;
  p.count = v.size();
  if (v.empty()) return p;
  // Nearest rank: the smallest value with at least q of the samples at or below it.
  const auto rank = [&](double q) {
    const auto r = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
    const auto nth = v.begin() + static_cast<std::ptrdiff_t>(std::max<std::size_t>(r, 1) - 1);
    std::nth_element(v.begin(), nth, v.end());
    return *nth;
  };
  p.p50_ms = rank(0.50);
  p.p95_ms = rank(0.95);
  p.p99_ms = rank(0.99);
  p.max_ms = *std::max_element(v.begin(), v.end());
  return p;
}

}  // namespace semap::common
