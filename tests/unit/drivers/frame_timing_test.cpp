#include "semap/drivers/frame_timing.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace semap::drivers {
namespace {

// 30 fps with one frame 5 ms late and two frames the driver skipped (sequence 10 -> 13).
TEST(FrameTiming, RateJitterAndSkippedFramesFromStampsAndSequences) {
  std::vector<common::Stamp> stamps;
  std::vector<std::uint32_t> sequences;
  const double period = 1.0 / 30.0;
  double t = 100.0;
  std::uint32_t seq = 0;
  for (int i = 0; i < 20; ++i) {
    const double late = i == 6 ? 0.005 : 0.0;
    stamps.push_back(common::Stamp::from_seconds(t + late));
    sequences.push_back(seq);
    const int step = i == 10 ? 3 : 1;
    t += step * period;
    seq += static_cast<std::uint32_t>(step);
  }
  const FrameTiming timing = measure_frame_timing(stamps, sequences, 30.0);
  EXPECT_EQ(timing.frames, 20u);
  EXPECT_EQ(timing.skipped, 2u);
  // 19 intervals over 21 periods (two skipped).
  EXPECT_NEAR(timing.fps, 19.0 / (21.0 * period), 1e-6);
  EXPECT_NEAR(timing.mean_interval_ms, 21.0 * period * 1e3 / 19.0, 1e-6);
  // The worst interval is the one across the skipped frames: 3 periods against 1.
  EXPECT_NEAR(timing.max_deviation_ms, 2e3 * period, 1e-6);
  EXPECT_GT(timing.jitter_ms, 5.0);
}

TEST(FrameTiming, SteadyStreamHasNoJitterAndSequenceWrapIsNoGap) {
  std::vector<common::Stamp> stamps;
  std::vector<std::uint32_t> sequences;
  for (int i = 0; i < 10; ++i) {
    stamps.push_back(common::Stamp::from_seconds(5.0 + 0.04 * i));
    sequences.push_back(0xFFFFFFFBu + static_cast<std::uint32_t>(i));  // wraps at i = 5
  }
  const FrameTiming timing = measure_frame_timing(stamps, sequences, 25.0);
  EXPECT_NEAR(timing.fps, 25.0, 1e-6);
  EXPECT_NEAR(timing.jitter_ms, 0.0, 1e-6);
  EXPECT_NEAR(timing.max_deviation_ms, 0.0, 1e-6);
  EXPECT_EQ(timing.skipped, 0u);
}

TEST(FrameTiming, FewerThanTwoFramesGiveNoRate) {
  const std::vector<common::Stamp> one{common::Stamp::from_seconds(1.0)};
  const std::vector<std::uint32_t> seq{7};
  const FrameTiming timing = measure_frame_timing(one, seq, 30.0);
  EXPECT_EQ(timing.frames, 1u);
  EXPECT_EQ(timing.fps, 0.0);
}

}  // namespace
}  // namespace semap::drivers
