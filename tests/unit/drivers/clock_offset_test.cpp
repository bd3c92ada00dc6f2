#include "semap/drivers/clock_offset.hpp"

#include <gtest/gtest.h>

namespace semap::drivers {
namespace {

TEST(RealtimeToMonotonic, MapsTheRealtimeNowOntoTheMonotonicNow) {
  RealtimeToMonotonic clock;
  const common::Stamp before = common::Stamp::now();
  timespec rt{};
  ::clock_gettime(CLOCK_REALTIME, &rt);
  const common::Stamp mapped = clock.convert(rt);
  const common::Stamp after = common::Stamp::now();
  // Within the offset's own uncertainty plus scheduling slack.
  EXPECT_GE(mapped.ns, before.ns - clock.uncertainty_ns() - 1'000'000);
  EXPECT_LE(mapped.ns, after.ns + clock.uncertainty_ns() + 1'000'000);
}

TEST(RealtimeToMonotonic, KeepsOrderBetweenRefreshes) {
  RealtimeToMonotonic clock(1'000'000'000'000);
  timespec a{};
  ::clock_gettime(CLOCK_REALTIME, &a);
  timespec b = a;
  b.tv_nsec += 1;
  if (b.tv_nsec >= 1'000'000'000) {
    b.tv_nsec -= 1'000'000'000;
    ++b.tv_sec;
  }
  const auto sa = clock.convert(a);
  const auto sb = clock.convert(b);
  EXPECT_EQ(sb.ns - sa.ns, 1);
}

}  // namespace
}  // namespace semap::drivers
