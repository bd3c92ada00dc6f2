#pragma once

// Per-scan timing figures that semap-dataset kitti-raw and semantickitti print.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace semap::apps {

// Nearest-rank percentile of the sorted `values` (not empty), in milliseconds.
inline double percentile_ms(const std::vector<double>& sorted, double fraction) {
  const auto rank = static_cast<std::size_t>(fraction * static_cast<double>(sorted.size()));
  return 1e3 * sorted[std::min(rank, sorted.size() - 1)];
}

}  // namespace semap::apps
