#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "semap/common/messages.hpp"

namespace semap::estimation {

struct GnssBufferCounters {
  std::uint64_t late = 0;       // older than the filter time: would be applied out of order
  std::uint64_t duplicate = 0;  // same stamp as a buffered fix
  std::uint64_t overflow = 0;   // buffer full, oldest dropped
};

// Holds GNSS fixes sorted by stamp until the filter time passes them, so fixes that arrive
// out of order (or ahead of the IMU) are applied in time order. A fix older than the filter
// time is refused: it can no longer be applied in order.
class GnssReorderBuffer {
 public:
  explicit GnssReorderBuffer(std::size_t capacity) : capacity_(capacity) {}

  // Returns false (and counts why) when the fix is not buffered.
  bool push(const common::GnssFix& fix, common::Stamp filter_time);
  // The oldest buffered fix with stamp <= until, removed from the buffer.
  std::optional<common::GnssFix> pop_until(common::Stamp until);

  std::size_t size() const { return fixes_.size(); }
  const GnssBufferCounters& counters() const { return counters_; }

 private:
  std::size_t capacity_;
  std::vector<common::GnssFix> fixes_;  // sorted by stamp; a handful of entries
  GnssBufferCounters counters_;
};

}  // namespace semap::estimation
