#include "semap/common/stamp.hpp"

#include <sys/time.h>
#include <time.h>

namespace semap::common {

Stamp Stamp::now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return from_timespec(ts);
}

Stamp Stamp::from_timespec(const timespec& ts) {
  return Stamp(static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec);
}

Stamp Stamp::from_timeval(const timeval& tv) {
  return Stamp(static_cast<std::int64_t>(tv.tv_sec) * 1'000'000'000 +
               static_cast<std::int64_t>(tv.tv_usec) * 1000);
}

timespec Stamp::to_timespec() const {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(ns / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(ns % 1'000'000'000);
  if (ts.tv_nsec < 0) {
    ts.tv_nsec += 1'000'000'000;
    ts.tv_sec -= 1;
  }
  return ts;
}

}  // namespace semap::common
