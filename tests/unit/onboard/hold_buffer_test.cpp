#include "semap/onboard/hold_buffer.hpp"

#include <gtest/gtest.h>

namespace semap::onboard {
namespace {

common::LabeledCloud cloud_at(double t, std::size_t points) {
  common::LabeledCloud c;
  c.stamp = common::Stamp::from_seconds(t);
  c.num_classes = 4;
  c.points.assign(points, Eigen::Vector3f::Zero());
  c.labels.assign(points, 1);
  c.probabilities.assign(points * 4, 0.25f);
  return c;
}

TEST(HoldBuffer, KeepsTheLastSecondsAndDropsTheOldestCounted) {
  HoldBuffer hold(2.0, std::size_t{1} << 30);
  for (int i = 0; i <= 10; ++i) hold.push(cloud_at(0.5 * i, 10), static_cast<std::uint32_t>(i));
  // Newest at 5 s: 3.0 .. 5.0 stay.
  ASSERT_EQ(hold.size(), 5u);
  EXPECT_EQ(hold.front().sequence, 6u);
  EXPECT_EQ(hold.dropped(), 6u);
  EXPECT_EQ(hold.bytes(), 5 * HoldBuffer::bytes_of(cloud_at(0.0, 10)));
}

TEST(HoldBuffer, StaysWithinItsBytesDroppingTheOldest) {
  const std::size_t one = HoldBuffer::bytes_of(cloud_at(0.0, 100));
  EXPECT_EQ(one, 100 * (sizeof(Eigen::Vector3f) + sizeof(std::uint16_t) + 4 * sizeof(float)));
  HoldBuffer hold(100.0, 3 * one + one / 2);
  for (int i = 0; i < 7; ++i) {
    hold.push(cloud_at(i, 100), static_cast<std::uint32_t>(i));
    EXPECT_LE(hold.bytes(), 3 * one + one / 2);
  }
  ASSERT_EQ(hold.size(), 3u);
  EXPECT_EQ(hold.front().sequence, 4u);
  EXPECT_EQ(hold.dropped(), 4u);
  hold.pop_front();  // taken out, not dropped
  EXPECT_EQ(hold.bytes(), 2 * one);
  EXPECT_EQ(hold.dropped(), 4u);
  // A cloud larger than the whole budget is not kept at all.
  hold.push(cloud_at(8.0, 1000), 8);
  EXPECT_TRUE(hold.empty());
  EXPECT_EQ(hold.bytes(), 0u);
  EXPECT_EQ(hold.dropped(), 7u);
}

TEST(HoldBuffer, DisabledHoldsNothing) {
  HoldBuffer off(0.0, 1000);
  EXPECT_FALSE(off.enabled());
  off.push(cloud_at(1.0, 1), 1);
  EXPECT_TRUE(off.empty());
  EXPECT_EQ(off.dropped(), 1u);
}

}  // namespace
}  // namespace semap::onboard
