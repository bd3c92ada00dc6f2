#pragma once

#include <cstdint>
#include <ctime>

#include "semap/common/stamp.hpp"

namespace semap::drivers {

// Maps CLOCK_REALTIME stamps (what socket timestamping gives) onto CLOCK_MONOTONIC (what the
// pipeline uses). The offset is measured as mono-realtime-mono with the narrowest of a few
// brackets, so a preemption between the two clock reads does not leak into it, and is held
// constant between refreshes so that consecutive stamps keep their order.
class RealtimeToMonotonic {
 public:
  explicit RealtimeToMonotonic(std::int64_t refresh_interval_ns = 1'000'000'000);

  common::Stamp convert(const timespec& realtime);
  std::int64_t offset_ns() const { return offset_ns_; }
  // Uncertainty of the current offset: half the width of its bracket.
  std::int64_t uncertainty_ns() const { return uncertainty_ns_; }

 private:
  void refresh(std::int64_t now_mono);

  std::int64_t refresh_interval_ns_;
  std::int64_t offset_ns_ = 0;  // realtime - monotonic
  std::int64_t uncertainty_ns_ = 0;
  std::int64_t last_refresh_ns_ = 0;
  bool valid_ = false;
};

}  // namespace semap::drivers
