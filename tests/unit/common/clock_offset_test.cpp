#include "semap/common/clock_offset.hpp"

#include <gtest/gtest.h>

#include <ctime>

namespace semap::common {
namespace {

std::int64_t realtime_now() {
  timespec rt{};
  ::clock_gettime(CLOCK_REALTIME, &rt);
  return Stamp::from_timespec(rt).ns;
}

TEST(ClockOffset, MapsTheRealtimeNowOntoTheMonotonicNow) {
  ClockOffset clock;
  const Stamp before = Stamp::now();
  const Stamp mapped = clock.to_monotonic(realtime_now());
  const Stamp after = Stamp::now();
  // Within the offset's own uncertainty plus scheduling slack.
  EXPECT_GE(mapped.ns, before.ns - clock.uncertainty_ns() - 1'000'000);
  EXPECT_LE(mapped.ns, after.ns + clock.uncertainty_ns() + 1'000'000);
}

TEST(ClockOffset, MapsTheMonotonicNowOntoTheRealtimeNow) {
  ClockOffset clock;
  const std::int64_t before = realtime_now();
  const std::int64_t mapped = clock.to_realtime(Stamp::now());
  const std::int64_t after = realtime_now();
  EXPECT_GE(mapped, before - clock.uncertainty_ns() - 1'000'000);
  EXPECT_LE(mapped, after + clock.uncertainty_ns() + 1'000'000);
}

TEST(ClockOffset, KeepsOrderAndInvertsExactlyBetweenRefreshes) {
  ClockOffset clock(1'000'000'000'000);
  const std::int64_t a = realtime_now();
  const Stamp sa = clock.to_monotonic(a);
  const Stamp sb = clock.to_monotonic(a + 1);
  EXPECT_EQ(sb.ns - sa.ns, 1);
  EXPECT_EQ(clock.to_realtime(sa), a);
}

}  // namespace
}  // namespace semap::common
