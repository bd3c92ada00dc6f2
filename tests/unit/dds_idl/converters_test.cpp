#include "semap/dds_idl/converters.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <ctime>

namespace semap::dds_idl {
namespace {

// Sets the process-wide stamp clock for one test and restores the default after it.
class StampClockScope {
 public:
  explicit StampClockScope(StampClock clock) { set_stamp_clock(clock); }
  ~StampClockScope() { set_stamp_clock(StampClock::kRealtime); }
};

TEST(Converters, MonotonicTimeSplitsIntoSecondsAndNanoseconds) {
  const StampClockScope monotonic(StampClock::kMonotonic);
  const msg::Time t = to_msg_time(common::Stamp(12'345'678'901));
  EXPECT_EQ(t.sec_, 12);
  EXPECT_EQ(t.nanosec_, 345'678'901u);
  EXPECT_EQ(from_msg_time(t).ns, 12'345'678'901);
  const msg::Time negative = to_msg_time(common::Stamp(-5));
  EXPECT_EQ(negative.sec_, 0);
  EXPECT_EQ(negative.nanosec_, 0u);
}

// By default headers carry ROS time: the system clock's now for a stamp of now (not seconds
// since boot), and a reader in the same process gets the monotonic stamp back.
TEST(Converters, HeadersCarryRosTimeByDefault) {
  ASSERT_EQ(stamp_clock(), StampClock::kRealtime);
  timespec before{};
  ::clock_gettime(CLOCK_REALTIME, &before);
  const common::Stamp now = common::Stamp::now();
  const msg::Time t = to_msg_time(now);
  timespec after{};
  ::clock_gettime(CLOCK_REALTIME, &after);
  EXPECT_GT(t.sec_, 1'600'000'000);  // after 2020: wall time, not uptime
  const std::int64_t ns = static_cast<std::int64_t>(t.sec_) * 1'000'000'000 + t.nanosec_;
  EXPECT_GE(ns, common::Stamp::from_timespec(before).ns - 1'000'000);
  EXPECT_LE(ns, common::Stamp::from_timespec(after).ns + 1'000'000);
  EXPECT_LE(std::abs(from_msg_time(t).ns - now.ns), 10'000);  // exact unless a refresh fell between
  EXPECT_EQ(stamp_clock_from_string("monotonic"), StampClock::kMonotonic);
  EXPECT_THROW(stamp_clock_from_string("gps"), std::invalid_argument);
}

TEST(Converters, ImuFollowsRosConventions) {
  common::ImuSample s;
  s.stamp = common::Stamp(2'000'000'000);
  s.gyro = {0.1, -0.2, 0.3};
  s.accel = {1.0, 2.0, 9.8};
  const std::string frame = "imu_link";
  msg::Imu m;
  to_msg(s, frame, 0.01, 0.04, m);
  EXPECT_STREQ(m.header_.frame_id_, "imu_link");
  EXPECT_EQ(m.orientation_covariance_[0], -1.0);  // no orientation
  EXPECT_EQ(m.angular_velocity_covariance_[0], 0.01);
  EXPECT_EQ(m.angular_velocity_covariance_[1], 0.0);
  EXPECT_EQ(m.linear_acceleration_covariance_[8], 0.04);
  const common::ImuSample back = from_msg(m);
  EXPECT_EQ(back.stamp, s.stamp);
  EXPECT_EQ(back.gyro, s.gyro);
  EXPECT_EQ(back.accel, s.accel);
}

TEST(Converters, NavSatFixStatusAndCovariance) {
  common::GnssFix f;
  f.latitude_deg = 48.1;
  f.longitude_deg = 11.5;
  f.altitude_m = 520.0;
  f.covariance << 1, 2, 3, 4, 5, 6, 7, 8, 9;
  const std::string frame = "gnss";
  msg::NavSatFix m;
  for (auto [q, status] :
       {std::pair{common::FixQuality::kInvalid, -1}, std::pair{common::FixQuality::kGps, 0},
        std::pair{common::FixQuality::kDgps, 1}, std::pair{common::FixQuality::kRtkFloat, 2}}) {
    f.quality = q;
    to_msg(f, frame, m);
    EXPECT_EQ(static_cast<std::int8_t>(m.status_.status_), status);  // int8 in an octet
    EXPECT_EQ(from_msg(m).quality == common::FixQuality::kInvalid, status == -1);
  }
  EXPECT_EQ(m.position_covariance_[1], 2.0);  // row-major
  EXPECT_EQ(m.position_covariance_[3], 4.0);
  const common::GnssFix back = from_msg(m);
  EXPECT_EQ(back.covariance, f.covariance);
  EXPECT_EQ(back.latitude_deg, 48.1);
}

TEST(Converters, OdometryRoundTrip) {
  PoseEstimate p;
  p.stamp = common::Stamp(99);
  p.position = {1, 2, 3};
  p.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 1, 0).normalized()));
  p.velocity_body = {4, 5, 6};
  p.angular_velocity_body = {0.1, 0.2, 0.3};
  for (int i = 0; i < 36; ++i) {
    p.pose_covariance(i / 6, i % 6) = i;
    p.twist_covariance(i / 6, i % 6) = 100 + i;
  }
  const std::string frame = "map";
  const std::string child = "base_link";
  msg::Odometry m;
  to_msg(p, frame, child, m);
  EXPECT_EQ(m.pose_.covariance_[1], 1.0);  // row-major (0,1)
  EXPECT_EQ(m.pose_.covariance_[6], 6.0);  // (1,0)
  EXPECT_EQ(m.pose_.pose_.orientation_.w_, p.orientation.w());
  const PoseEstimate back = from_msg(m);
  EXPECT_EQ(back.position, p.position);
  EXPECT_TRUE(back.orientation.isApprox(p.orientation));
  EXPECT_EQ(back.velocity_body, p.velocity_body);
  EXPECT_EQ(back.pose_covariance, p.pose_covariance);
  EXPECT_EQ(back.twist_covariance, p.twist_covariance);

  msg::PoseWithCovarianceStamped ps;
  to_msg(p, frame, ps);
  EXPECT_EQ(from_msg(ps).pose_covariance, p.pose_covariance);
}

}  // namespace
}  // namespace semap::dds_idl
