#include "semap/common/clock_offset.hpp"

#include <ctime>
#include <limits>

namespace semap::common {
namespace {

std::int64_t read_ns(clockid_t clock) {
  timespec ts{};
  ::clock_gettime(clock, &ts);
  return Stamp::from_timespec(ts).ns;
}

constexpr int kBrackets = 5;

}  // namespace

ClockOffset::ClockOffset(std::int64_t refresh_interval_ns)
    : refresh_interval_ns_(refresh_interval_ns) {}

void ClockOffset::refresh_if_due() {
  const std::int64_t now = read_ns(CLOCK_MONOTONIC);
  if (valid_ && now - last_refresh_ns_ < refresh_interval_ns_) return;
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
  last_refresh_ns_ = now;
  valid_ = true;
}

Stamp ClockOffset::to_monotonic(std::int64_t realtime_ns) {
  refresh_if_due();
  return Stamp(realtime_ns - offset_ns_);
}

std::int64_t ClockOffset::to_realtime(Stamp monotonic) {
  refresh_if_due();
  return monotonic.ns + offset_ns_;
}

}  // namespace semap::common
