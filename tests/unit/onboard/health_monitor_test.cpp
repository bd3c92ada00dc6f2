#include "semap/onboard/health_monitor.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "semap/onboard/mapping_stage.hpp"
#include "semap/onboard/write_failure_log.hpp"

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
  s.longest_gap_s = 3.25;
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
  EXPECT_FLOAT_EQ(d.longest_gap_s, 3.25f);
}

// A full disk reaches the health report: the checkpoint's and the pager's failures on the one
// log, the error of whichever is failing, through the DDS message and back.
TEST(HealthMonitor, CheckpointWriteFailuresReachTheReportAndTheMessage) {
  MappingStageStats stats;
  stats.checkpoint.checkpoints = 12;
  stats.checkpoint.write_failures = 5;
  stats.checkpoint.failing = true;
  stats.checkpoint.last_error = "/data/map.smap.log: write: No space left on device";
  stats.pager.write_failures = 2;
  stats.pager.last_error = "/data/map.smap.log: write: File too large";
  const auto w = checkpoint_health(stats, "/data/map.smap.log");
  EXPECT_EQ(w.name, "map_checkpoint");
  EXPECT_EQ(w.writes, 12u);
  EXPECT_EQ(w.failures, 7u);
  EXPECT_TRUE(w.failing);
  EXPECT_EQ(w.last_error, stats.checkpoint.last_error);

  HealthMonitor m;
  const auto report = m.report(common::Stamp::from_seconds(5.0), {}, {}, {w});
  const dds_idl::HealthMessage message(report, "base_link");
  const auto back = dds_idl::from_msg(message.get());
  ASSERT_EQ(back.writers.size(), 1u);
  EXPECT_EQ(back.writers[0].path, "/data/map.smap.log");
  EXPECT_EQ(back.writers[0].failures, 7u);
  EXPECT_TRUE(back.writers[0].failing);
  EXPECT_EQ(back.writers[0].last_error, stats.checkpoint.last_error);

  // Once the checkpoint writes again, only the pager's failing would be reported.
  stats.checkpoint.failing = false;
  stats.pager.failing = true;
  EXPECT_EQ(checkpoint_health(stats, "x").last_error, stats.pager.last_error);
}

// A disk that stays full must not flood the log: the first failure, one reminder per interval
// however many failures came in it, and the recovery.
TEST(WriteFailureLog, FirstFailureThenOneReminderPerIntervalThenTheRecovery) {
  WriteFailureLog log("test", "map checkpoint", "retrying", std::chrono::milliseconds(200));
  log.update(0, false, "");
  EXPECT_EQ(log.lines(), 0u);
  log.update(1, true, "map.log: write: No space left on device");
  EXPECT_EQ(log.lines(), 1u);
  for (std::uint64_t f = 2; f <= 50; ++f) log.update(f, true, "map.log: write: ...");
  EXPECT_EQ(log.lines(), 1u);  // within the interval: counted, not logged
  std::this_thread::sleep_for(std::chrono::milliseconds(250));
  log.update(51, true, "map.log: write: ...");
  EXPECT_EQ(log.lines(), 2u);  // one reminder with the 50 since
  log.update(51, false, "");
  EXPECT_EQ(log.lines(), 3u);  // writing again
  log.update(51, false, "");
  EXPECT_EQ(log.lines(), 3u);
  log.update(52, true, "again");  // a new episode starts with its own first line
  EXPECT_EQ(log.lines(), 4u);
}

// The viewer's clients (what each was sent and lost for being behind) through the message.
TEST(HealthMonitor, ViewerClientsReachTheMessage) {
  HealthMonitor m;
  auto report = m.report(common::Stamp::from_seconds(5.0), {}, {}, {});
  report.viewers.push_back({"127.0.0.1:50000", 123456, 789, 12, 3.5f});
  const dds_idl::HealthMessage message(report, "base_link");
  const auto back = dds_idl::from_msg(message.get());
  ASSERT_EQ(back.viewers.size(), 1u);
  EXPECT_EQ(back.viewers[0].address, "127.0.0.1:50000");
  EXPECT_EQ(back.viewers[0].bytes_sent, 123456u);
  EXPECT_EQ(back.viewers[0].messages_sent, 789u);
  EXPECT_EQ(back.viewers[0].messages_dropped, 12u);
  EXPECT_FLOAT_EQ(back.viewers[0].connected_s, 3.5f);
}

}  // namespace
}  // namespace semap::onboard
