#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>

#include "semap/common/messages.hpp"

namespace semap::onboard {

// The clouds (body frame) of frames taken before the filter's heading was known, kept until
// poses for their stamps exist (map.hold_seconds, map.hold_bytes): holding a frame costs its
// cloud's memory, so both bounds are hard, and the oldest clouds go first, counted, when the
// newest would pass either. One owner thread (the perception stage).
class HoldBuffer {
 public:
  struct Held {
    common::LabeledCloud cloud;
    std::uint32_t sequence = 0;
  };

  // max_seconds <= 0 or max_bytes == 0: holds nothing (every push is dropped).
  HoldBuffer(double max_seconds, std::size_t max_bytes);

  bool enabled() const { return max_seconds_ > 0.0 && max_bytes_ > 0; }
  // Keeps the cloud, then drops the oldest until the held stamps span at most max_seconds and
  // the clouds take at most max_bytes (the new cloud too, if it alone is larger).
  void push(common::LabeledCloud cloud, std::uint32_t sequence);
  bool empty() const { return held_.empty(); }
  std::size_t size() const { return held_.size(); }
  std::size_t bytes() const { return bytes_; }
  Held& front() { return held_.front(); }
  void pop_front();
  // Clouds dropped to stay within the bounds.
  std::uint64_t dropped() const { return dropped_; }

  // The memory a cloud's points, labels and probabilities take.
  static std::size_t bytes_of(const common::LabeledCloud& cloud);

 private:
  double max_seconds_;
  std::size_t max_bytes_;
  std::deque<Held> held_;
  std::size_t bytes_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace semap::onboard
