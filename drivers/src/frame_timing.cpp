#include "semap/drivers/frame_timing.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace semap::drivers {

FrameTiming measure_frame_timing(std::span<const common::Stamp> stamps,
                                 std::span<const std::uint32_t> sequences, double nominal_fps) {
  FrameTiming t;
  t.frames = stamps.size();
  if (stamps.size() < 2) return t;
  std::vector<double> intervals_ms;
  for (std::size_t i = 1; i < stamps.size(); ++i) {
    intervals_ms.push_back(1e3 * common::seconds_between(stamps[i], stamps[i - 1]));
  }
  const double n = static_cast<double>(intervals_ms.size());
  double sum = 0;
  for (const double v : intervals_ms) sum += v;
  t.mean_interval_ms = sum / n;
  double square = 0;
  for (const double v : intervals_ms) square += (v - t.mean_interval_ms) * (v - t.mean_interval_ms);
  t.jitter_ms = std::sqrt(square / n);
  const double span_s = common::seconds_between(stamps.back(), stamps.front());
  t.fps = span_s > 0 ? n / span_s : 0;
  const double expected_ms = nominal_fps > 0 ? 1e3 / nominal_fps : t.mean_interval_ms;
  for (const double v : intervals_ms) {
    t.max_deviation_ms = std::max(t.max_deviation_ms, std::abs(v - expected_ms));
  }
  for (std::size_t i = 1; i < sequences.size(); ++i) {
    // Unsigned difference: a sequence counter wrapping at 2^32 still counts right.
    const std::uint32_t step = sequences[i] - sequences[i - 1];
    if (step > 1) t.skipped += step - 1;
  }
  return t;
}

}  // namespace semap::drivers
