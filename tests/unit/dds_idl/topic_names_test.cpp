#include "semap/dds_idl/topic_names.hpp"

#include <gtest/gtest.h>

namespace semap::dds_idl {
namespace {

TEST(TopicNames, FollowRosTwoMapping) {
  EXPECT_EQ(topic_name("", SemapTopic::kOdometry), "rt/semap/odometry");
  EXPECT_EQ(topic_name("robot1", SemapTopic::kMapBlocks), "rt/robot1/semap/map_blocks");
  EXPECT_EQ(topic_name("fleet/robot_2", SemapTopic::kMapCloud), "rt/fleet/robot_2/semap/map_cloud");
  for (const char* bad :
       {"/robot", "robot/", "a//b", "1robot", "fleet/2", "a/2b", "ro-bot", "ro bot"}) {
    EXPECT_THROW(topic_name(bad, SemapTopic::kPose), std::invalid_argument) << bad;
  }
}

TEST(TopicNames, QosMatchesTheDesign) {
  dds_reliability_kind_t rel;
  dds_duration_t blocking;
  dds_durability_kind_t dur;
  dds_history_kind_t hist;
  int32_t depth;
  const Qos blocks = topic_qos(SemapTopic::kMapBlocks);
  ASSERT_TRUE(dds_qget_reliability(blocks.get(), &rel, &blocking));
  EXPECT_EQ(rel, DDS_RELIABILITY_RELIABLE);
  ASSERT_TRUE(dds_qget_durability(blocks.get(), &dur));
  EXPECT_EQ(dur, DDS_DURABILITY_TRANSIENT_LOCAL);
  ASSERT_TRUE(dds_qget_history(blocks.get(), &hist, &depth));
  EXPECT_EQ(hist, DDS_HISTORY_KEEP_LAST);
  EXPECT_EQ(depth, 1);

  const Qos odom = topic_qos(SemapTopic::kOdometry);
  ASSERT_TRUE(dds_qget_reliability(odom.get(), &rel, &blocking));
  EXPECT_EQ(rel, DDS_RELIABILITY_BEST_EFFORT);
  // dds.sensor_reliability: reliable, for subscribers with ROS's default QoS; same depth.
  const Qos reliable_imu = topic_qos(SemapTopic::kImu, SensorReliability::kReliable);
  ASSERT_TRUE(dds_qget_reliability(reliable_imu.get(), &rel, &blocking));
  EXPECT_EQ(rel, DDS_RELIABILITY_RELIABLE);
  ASSERT_TRUE(dds_qget_history(reliable_imu.get(), &hist, &depth));
  EXPECT_EQ(depth, 10);
  EXPECT_EQ(sensor_reliability_from_string("reliable"), SensorReliability::kReliable);
  EXPECT_THROW(sensor_reliability_from_string("sometimes"), std::invalid_argument);

  const Qos health = topic_qos(SemapTopic::kHealth);
  ASSERT_TRUE(dds_qget_reliability(health.get(), &rel, &blocking));
  EXPECT_EQ(rel, DDS_RELIABILITY_RELIABLE);
  ASSERT_TRUE(dds_qget_history(health.get(), &hist, &depth));
  EXPECT_EQ(depth, 10);
}

}  // namespace
}  // namespace semap::dds_idl
