#include "semap/common/latency_window.hpp"

#include <gtest/gtest.h>

#include <thread>

namespace semap::common {
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

TEST(LatencyWindow, KeepsTheMaximumOfTheWindow) {
  LatencyWindow w(4);
  for (const double s : {0.003, 0.010, 0.002, 0.001}) w.record(s);
  EXPECT_FLOAT_EQ(w.percentiles().max_ms, 10.0f);
  w.record(0.004);  // the oldest, 3 ms, leaves the window
  EXPECT_FLOAT_EQ(w.percentiles().max_ms, 10.0f);
  w.record(0.004);  // then the 10 ms one
  EXPECT_FLOAT_EQ(w.percentiles().max_ms, 4.0f);
}

}  // namespace
}  // namespace semap::common
