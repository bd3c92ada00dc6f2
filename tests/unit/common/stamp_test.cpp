#include "semap/common/stamp.hpp"

#include <gtest/gtest.h>
#include <time.h>

namespace semap::common {
namespace {

TEST(Stamp, ConversionsRoundTrip) {
  const Stamp s = Stamp::from_seconds(12.345678901);
  EXPECT_EQ(s.ns, 12'345'678'901);
  EXPECT_DOUBLE_EQ(s.seconds(), 12.345678901);
  EXPECT_EQ(Stamp::from_micros(1'500'000).ns, 1'500'000'000);
  EXPECT_EQ(s.micros(), 12'345'678);
  const timespec ts = s.to_timespec();
  EXPECT_EQ(ts.tv_sec, 12);
  EXPECT_EQ(ts.tv_nsec, 345'678'901);
  EXPECT_EQ(Stamp::from_timespec(ts), s);
}

TEST(Stamp, NegativeTimespecIsNormalised) {
  const timespec ts = Stamp(-1).to_timespec();
  EXPECT_EQ(ts.tv_sec, -1);
  EXPECT_EQ(ts.tv_nsec, 999'999'999);
}

TEST(Stamp, NowIsMonotonicAndOrdered) {
  const Stamp a = Stamp::now();
  const Stamp b = Stamp::now();
  EXPECT_LE(a, b);
  EXPECT_NEAR(seconds_between(a + 0.25, a), 0.25, 1e-9);
}

}  // namespace
}  // namespace semap::common
