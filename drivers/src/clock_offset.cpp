#include "semap/drivers/clock_offset.hpp"

#include <limits>

namespace semap::drivers {
namespace {

std::int64_t read_ns(clockid_t clock) {
  timespec ts{};
  ::clock_gettime(clock, &ts);
  return common::Stamp::from_timespec(ts).ns;
}

constexpr int kBrackets = 5;

}  // namespace

RealtimeToMonotonic::RealtimeToMonotonic(std::int64_t refresh_interval_ns)
    : refresh_interval_ns_(refresh_interval_ns) {}

void RealtimeToMonotonic::refresh(std::int64_t now_mono) {
  std::int64_t best_width = std::numeric_limits<std::int64_t>::max();
  for (int i = 0; i < kBrackets; ++i) {
    const std::int64_t before = read_ns(CLOCK_MONOTONIC);
    const std::int64_t rt = read_ns(CLOCK_REALTIME);
    const std::int64_t after = read_ns(CLOCK_MONOTONIC);
    if (after - before < best_width) {
      best_width = after - before;
      offset_ns_ = rt - (before + (after - before) / 2);
    }
  }
  uncertainty_ns_ = best_width / 2;
  last_refresh_ns_ = now_mono;
  valid_ = true;
}

common::Stamp RealtimeToMonotonic::convert(const timespec& realtime) {
  const std::int64_t now = read_ns(CLOCK_MONOTONIC);
  if (!valid_ || now - last_refresh_ns_ >= refresh_interval_ns_) refresh(now);
  return common::Stamp(common::Stamp::from_timespec(realtime).ns - offset_ns_);
}

}  // namespace semap::drivers
