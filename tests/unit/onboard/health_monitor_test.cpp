#include "semap/onboard/health_monitor.hpp"

#include <gtest/gtest.h>

namespace semap::onboard {
namespace {

TEST(HealthMonitor, RatesComeFromCountGrowthBetweenReports) {
  HealthMonitor m;
  const common::Stamp t0 = common::Stamp::from_seconds(100.0);
  auto r =
      m.report(t0, {{"estimation", 1000, 3, 2, {.p50_ms = 1.0f, .p99_ms = 4.0f, .count = 10}}}, {});
  ASSERT_EQ(r.stages.size(), 1u);
  EXPECT_EQ(r.stages[0].rate_hz, 0.0f);  // nothing to compare with yet
  EXPECT_EQ(r.stages[0].queue_depth, 3u);
  EXPECT_EQ(r.stages[0].drops, 2u);
  EXPECT_FLOAT_EQ(r.stages[0].latency_p99_ms, 4.0f);
  r = m.report(t0 + 0.5, {{"estimation", 1200, 0, 2, {}}, {"mapping", 7, 0, 0, {}}}, {});
  EXPECT_FLOAT_EQ(r.stages[0].rate_hz, 400.0f);
  EXPECT_EQ(r.stages[1].rate_hz, 0.0f);
  EXPECT_EQ(r.stamp, t0 + 0.5);
}

TEST(HealthMonitor, DriverCountersSumIntegrityAndLosses) {
  drivers::DriverStats s;
  s.frames = 50;
  s.checksum_failures = 2;
  s.errors = 1;
  s.input_drops = 3;
  s.sequence_gaps = 4;
  s.ring_drops = 5;
  s.reconnects = 1;
  s.bus_off = 6;
  s.error_passive = 7;
  s.bus_restarts = 8;
  s.wakeup = {.p50_ms = 0.1f, .p99_ms = 0.4f, .max_ms = 2.5f, .count = 100};
  const auto d = driver_health("imu", s);
  EXPECT_EQ(d.name, "imu");
  EXPECT_EQ(d.frames, 50u);
  EXPECT_EQ(d.bad_frames, 3u);
  EXPECT_EQ(d.dropped, 12u);
  EXPECT_EQ(d.reconnects, 1u);
  EXPECT_EQ(d.bus_off, 6u);
  EXPECT_EQ(d.error_passive, 7u);
  EXPECT_EQ(d.bus_restarts, 8u);
  EXPECT_FLOAT_EQ(d.wakeup_p50_ms, 0.1f);
  EXPECT_FLOAT_EQ(d.wakeup_p99_ms, 0.4f);
  EXPECT_FLOAT_EQ(d.wakeup_max_ms, 2.5f);
}

}  // namespace
}  // namespace semap::onboard
