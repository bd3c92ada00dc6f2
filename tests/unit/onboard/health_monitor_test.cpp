#include "semap/onboard/health_monitor.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace semap::onboard {
namespace {

TEST(LatencyWindow, NearestRankPercentilesOfTheLastItems) {
  LatencyWindow w(100);
  EXPECT_EQ(w.percentiles().count, 0u);
  for (int i = 1; i <= 100; ++i) w.record(i * 1e-3);  // 1 .. 100 ms
  auto p = w.percentiles();
  EXPECT_EQ(p.count, 100u);
  EXPECT_FLOAT_EQ(p.p50_ms, 50.0f);
  EXPECT_FLOAT_EQ(p.p95_ms, 95.0f);
  EXPECT_FLOAT_EQ(p.p99_ms, 99.0f);
  // The window keeps the last 100: fifty more of 1 s push the median up to 1 s.
  for (int i = 0; i < 50; ++i) w.record(1.0);
  p = w.percentiles();
  EXPECT_EQ(p.count, 100u);
  EXPECT_FLOAT_EQ(p.p50_ms, 100.0f);
  EXPECT_FLOAT_EQ(p.p99_ms, 1000.0f);
}

TEST(LatencyWindow, RecordsFromAnotherThreadWhileRead) {
  LatencyWindow w(64);
  std::jthread writer([&] {
    for (int i = 0; i < 20000; ++i) w.record(2e-3);
  });
  for (int i = 0; i < 200; ++i) {
    const auto p = w.percentiles();
    if (p.count > 0) {
      EXPECT_FLOAT_EQ(p.p50_ms, 2.0f);
    }
  }
}

TEST(HealthMonitor, RatesComeFromCountGrowthBetweenReports) {
  HealthMonitor m;
  const common::Stamp t0 = common::Stamp::from_seconds(100.0);
  auto r = m.report(t0, {{"estimation", 1000, 3, 2, {1.0f, 3.0f, 4.0f, 10}}}, {});
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
  const auto d = driver_health("imu", s);
  EXPECT_EQ(d.name, "imu");
  EXPECT_EQ(d.frames, 50u);
  EXPECT_EQ(d.bad_frames, 3u);
  EXPECT_EQ(d.dropped, 12u);
  EXPECT_EQ(d.reconnects, 1u);
  EXPECT_EQ(d.bus_off, 6u);
  EXPECT_EQ(d.error_passive, 7u);
  EXPECT_EQ(d.bus_restarts, 8u);
}

}  // namespace
}  // namespace semap::onboard
