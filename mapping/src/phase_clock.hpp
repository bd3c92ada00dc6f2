#pragma once

// Internal to semap_mapping: wall time of the insertion's phases (InsertPhases).

#include <chrono>

namespace semap::mapping::detail {

// Seconds between successive lap() calls.
class PhaseClock {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace semap::mapping::detail
