#pragma once

#include <cstdint>

#include "semap/common/stamp.hpp"

namespace semap::common {

// The offset CLOCK_REALTIME - CLOCK_MONOTONIC, for the pipeline's edges: socket timestamps
// arrive in realtime and go onto the monotonic clock the pipeline uses; DDS headers leave in
// realtime (ROS time) while the pipeline stays monotonic. The offset is measured as
// mono-realtime-mono with the narrowest of a few brackets, so a preemption between the two
// clock reads does not leak into it, and is held constant between refreshes so that
// consecutive stamps keep their order and a conversion and its inverse agree.
class ClockOffset {
 public:
  explicit ClockOffset(std::int64_t refresh_interval_ns = 1'000'000'000);

  Stamp to_monotonic(std::int64_t realtime_ns);
  std::int64_t to_realtime(Stamp monotonic);

  std::int64_t offset_ns() const { return offset_ns_; }
  // Uncertainty of the current offset: half the width of its bracket.
  std::int64_t uncertainty_ns() const { return uncertainty_ns_; }

 private:
  void refresh_if_due();

  std::int64_t refresh_interval_ns_;
  std::int64_t offset_ns_ = 0;  // realtime - monotonic
  std::int64_t uncertainty_ns_ = 0;
  std::int64_t last_refresh_ns_ = 0;
  bool valid_ = false;
};

}  // namespace semap::common
