#pragma once

#include <compare>
#include <cstdint>

struct timespec;
struct timeval;

namespace semap::common {

// A point in time on CLOCK_MONOTONIC, in nanoseconds. Every timestamp inside the pipeline is
// a Stamp so that samples from different drivers can be ordered and interpolated.
struct Stamp {
  std::int64_t ns = 0;

  constexpr Stamp() = default;
  constexpr explicit Stamp(std::int64_t nanoseconds) : ns(nanoseconds) {}

  static Stamp now();
  static constexpr Stamp from_seconds(double s) {
    return Stamp(static_cast<std::int64_t>(s * 1e9 + (s >= 0 ? 0.5 : -0.5)));
  }
  static constexpr Stamp from_micros(std::int64_t us) { return Stamp(us * 1000); }
  static Stamp from_timespec(const timespec& ts);
  static Stamp from_timeval(const timeval& tv);

  constexpr double seconds() const { return static_cast<double>(ns) * 1e-9; }
  constexpr std::int64_t micros() const { return ns / 1000; }
  timespec to_timespec() const;

  constexpr auto operator<=>(const Stamp&) const = default;
};

// Signed difference a - b in seconds.
constexpr double seconds_between(Stamp a, Stamp b) {
  return static_cast<double>(a.ns - b.ns) * 1e-9;
}

constexpr Stamp operator+(Stamp s, double seconds) {
  return Stamp(s.ns + Stamp::from_seconds(seconds).ns);
}

}  // namespace semap::common
