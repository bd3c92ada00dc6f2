// Every standard type from a publisher process to readers here, values checked field by field.
#include <thread>

#include "dds_fixture.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/health.hpp"
#include "semap/dds_idl/map_cloud.hpp"
#include "semap/dds_idl/reader.hpp"
#include "semap/dds_idl/topic_names.hpp"
#include "test_blocks.hpp"

namespace semap::dds_idl::testing {
namespace {

// Waits until one sample arrived and hands a copy of what f extracts from it.
template <typename T, typename F>
auto first_sample(const Participant& p, const std::string& ns, SemapTopic which, F&& f) {
  Topic<T> topic(p, topic_name(ns, which));
  Reader<T> reader(p, topic, topic_qos(which));
  std::optional<decltype(f(std::declval<const T&>()))> out;
  const auto deadline = std::chrono::steady_clock::now() + seconds(10);
  while (!out && std::chrono::steady_clock::now() < deadline) {
    reader.wait(milliseconds(100));
    reader.take_each([&](const T& m, const dds_sample_info_t&) {
      if (!out) out = f(m);
    });
  }
  return out;
}

TEST_F(DdsTest, PublisherAndListenerExchangeEveryType) {
  const std::string ns = unique_ns("types");
  ChildProcess pub(peer("types-pub", {"--ns", ns, "--classes", "5", "--seconds", "40"}));
  ASSERT_TRUE(pub.expect("publishing", seconds(10)));
  Participant p(test_domain());

  const auto imu = first_sample<msg::Imu>(p, ns, SemapTopic::kImu, [](const msg::Imu& m) {
    EXPECT_STREQ(m.header_.frame_id_, "imu");
    EXPECT_EQ(m.orientation_covariance_[0], -1.0);
    EXPECT_DOUBLE_EQ(m.angular_velocity_covariance_[4], 1e-4);
    return from_msg(m);
  });
  ASSERT_TRUE(imu);
  EXPECT_TRUE(imu->gyro.isApprox(Eigen::Vector3d(0.1, 0.2, 0.3)));
  EXPECT_TRUE(imu->accel.isApprox(Eigen::Vector3d(0.0, 0.0, 9.81)));
  EXPECT_GT(imu->stamp.ns, 0);

  const auto fix =
      first_sample<msg::NavSatFix>(p, ns, SemapTopic::kGnss, [](const msg::NavSatFix& m) {
        EXPECT_EQ(m.status_.status_, sensor_msgs_msg_dds__NavSatStatus_Constants_STATUS_GBAS_FIX_);
        return from_msg(m);
      });
  ASSERT_TRUE(fix);
  EXPECT_DOUBLE_EQ(fix->latitude_deg, 52.1);
  EXPECT_DOUBLE_EQ(fix->longitude_deg, 4.3);
  EXPECT_DOUBLE_EQ(fix->altitude_m, 12.5);
  EXPECT_EQ(fix->quality, common::FixQuality::kRtkFixed);

  const auto odom =
      first_sample<msg::Odometry>(p, ns, SemapTopic::kOdometry, [](const msg::Odometry& m) {
        EXPECT_STREQ(m.header_.frame_id_, "map");
        EXPECT_STREQ(m.child_frame_id_, "base_link");
        return from_msg(m);
      });
  ASSERT_TRUE(odom);
  EXPECT_TRUE(odom->position.isApprox(Eigen::Vector3d(1.0, 2.0, 3.0)));
  EXPECT_NEAR(odom->orientation.angularDistance(
                  Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()))),
              0.0, 1e-12);
  EXPECT_TRUE(odom->velocity_body.isApprox(Eigen::Vector3d(0.5, 0.0, 0.0)));

  const auto pose = first_sample<msg::PoseWithCovarianceStamped>(
      p, ns, SemapTopic::kPose,
      [](const msg::PoseWithCovarianceStamped& m) { return from_msg(m); });
  ASSERT_TRUE(pose);
  EXPECT_TRUE(pose->position.isApprox(Eigen::Vector3d(1.0, 2.0, 3.0)));

  const auto health = first_sample<msg::Health>(p, ns, SemapTopic::kHealth,
                                                [](const msg::Health& m) { return from_msg(m); });
  ASSERT_TRUE(health);
  ASSERT_EQ(health->stages.size(), 1u);
  ASSERT_EQ(health->drivers.size(), 1u);
  EXPECT_EQ(health->stages[0].name, "mapping");
  EXPECT_FLOAT_EQ(health->stages[0].rate_hz, 9.5f);
  EXPECT_EQ(health->stages[0].queue_depth, 3u);
  EXPECT_EQ(health->stages[0].drops, 2u);
  EXPECT_FLOAT_EQ(health->stages[0].latency_p99_ms, 4.0f);
  EXPECT_EQ(health->drivers[0].name, "can_imu");
  EXPECT_EQ(health->drivers[0].frames, 4000u);
  EXPECT_EQ(health->drivers[0].bad_frames, 1u);
  EXPECT_GT(health->stamp.ns, 0);

  const auto cloud = first_sample<msg::PointCloud2>(
      p, ns, SemapTopic::kMapCloud, [](const msg::PointCloud2& m) { return read_map_cloud(m); });
  ASSERT_TRUE(cloud);
  const BlockSnapshot block = make_block({0, 0, 0}, 1, 5, false);
  std::vector<CloudPoint> expected;
  for (std::size_t i = 0; i < block.cell_count(); ++i) {
    if (block.state[i] == common::CellState::kOccupied) {
      expected.push_back({block.cell_center(i), block.argmax_class[i], block.variance[i]});
    }
  }
  ASSERT_EQ(cloud->size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_TRUE((*cloud)[i].position.isApprox(expected[i].position));
    EXPECT_EQ((*cloud)[i].cls, expected[i].cls);
    EXPECT_EQ((*cloud)[i].variance, expected[i].variance);
  }
}

}  // namespace
}  // namespace semap::dds_idl::testing
