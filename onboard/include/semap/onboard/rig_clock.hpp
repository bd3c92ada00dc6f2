#pragma once

#include <time.h>

#include <algorithm>
#include <cstdint>
#include <stop_token>

#include "semap/common/stamp.hpp"

namespace semap::onboard {

// Sleeps until `when` (CLOCK_MONOTONIC) in slices of at most 20 ms, so a stop request is
// honoured promptly.
inline void sleep_until(common::Stamp when, std::stop_token stop) {
  while (!stop.stop_requested()) {
    const common::Stamp now = common::Stamp::now();
    if (now >= when) return;
    const auto wait = std::min<std::int64_t>(when.ns - now.ns, 20'000'000);
    const timespec ts = common::Stamp(wait).to_timespec();
    nanosleep(&ts, nullptr);
  }
}

}  // namespace semap::onboard
