// One serialization: what a MessageTap receives from a Writer is the CDR DDS delivers, byte for
// byte, and deserialises to the sample written (odometry, an occupancy grid), on loopback.
#include <gtest/gtest.h>

#include <mutex>
#include <vector>

#include "dds_fixture.hpp"
#include "semap/dds_idl/message_tap.hpp"
#include "semap/dds_idl/reader.hpp"
#include "semap/dds_idl/ros2msg.hpp"
#include "semap/dds_idl/topic_names.hpp"
#include "semap/dds_idl/writer.hpp"

namespace semap::dds_idl::testing {
namespace {

class RecordingTap : public MessageTap {
 public:
  std::uint32_t add_channel(const TapChannel& channel) override {
    channels.push_back(channel);
    return static_cast<std::uint32_t>(channels.size() - 1);
  }
  void on_message(std::uint32_t channel, common::Stamp,
                  std::span<const std::uint8_t> cdr) noexcept override {
    std::lock_guard lock(mutex);
    messages.emplace_back(channel, std::vector<std::uint8_t>(cdr.begin(), cdr.end()));
  }
  std::vector<TapChannel> channels;
  std::mutex mutex;
  std::vector<std::pair<std::uint32_t, std::vector<std::uint8_t>>> messages;
};

template <typename T>
std::vector<std::uint8_t> received_cdr(Reader<T>& reader) {
  std::vector<std::uint8_t> out;
  const auto deadline = std::chrono::steady_clock::now() + seconds(10);
  while (out.empty() && std::chrono::steady_clock::now() < deadline) {
    reader.wait(milliseconds(100));
    reader.take_each_cdr([&](std::span<const std::uint8_t> cdr, const dds_sample_info_t&) {
      out.assign(cdr.begin(), cdr.end());
    });
  }
  return out;
}

class TapTest : public DdsTest {};

TEST_F(TapTest, OdometryBytesAreWhatDdsDeliversAndReadBack) {
  Participant participant(static_cast<dds_domainid_t>(test_domain()));
  const std::string ns = unique_ns("tap");
  const Qos qos = topic_qos(SemapTopic::kOdometry, SensorReliability::kReliable);
  Topic<msg::Odometry> topic(participant, topic_name(ns, SemapTopic::kOdometry), qos);
  Reader<msg::Odometry> reader(participant, topic, qos);
  Writer<msg::Odometry> writer(participant, topic, qos);
  RecordingTap tap;
  writer.attach_tap(tap);
  ASSERT_EQ(tap.channels.size(), 1u);
  EXPECT_EQ(tap.channels[0].topic, "/" + ns + "/semap/odometry");
  EXPECT_EQ(tap.channels[0].type, "nav_msgs/msg/Odometry");
  EXPECT_FALSE(tap.channels[0].latched);
  EXPECT_NO_THROW(ros2msg_schema(tap.channels[0].type));

  msg::Odometry m{};
  m.header_.stamp_.sec_ = 12;
  m.header_.stamp_.nanosec_ = 345;
  m.header_.frame_id_ = const_cast<char*>("map");
  m.child_frame_id_ = const_cast<char*>("base_link");
  m.pose_.pose_.position_.x_ = 1.5;
  m.pose_.pose_.position_.y_ = -2.25;
  m.pose_.pose_.orientation_.w_ = 1.0;
  for (int i = 0; i < 36; ++i) m.pose_.covariance_[i] = i * 0.5;
  m.twist_.twist_.linear_.x_ = 3.0;
  ASSERT_TRUE(writer.wait_for_readers(1, std::chrono::milliseconds(5000)));
  writer.write(m);

  const auto dds_bytes = received_cdr(reader);
  ASSERT_FALSE(dds_bytes.empty());
  ASSERT_EQ(tap.messages.size(), 1u);
  EXPECT_EQ(tap.messages[0].second, dds_bytes);

  msg::Odometry back{};
  ASSERT_TRUE(deserialize_cdr(std::span<const std::uint8_t>(tap.messages[0].second), back));
  EXPECT_EQ(back.header_.stamp_.sec_, 12);
  EXPECT_EQ(back.header_.stamp_.nanosec_, 345u);
  EXPECT_STREQ(back.header_.frame_id_, "map");
  EXPECT_STREQ(back.child_frame_id_, "base_link");
  EXPECT_EQ(back.pose_.pose_.position_.y_, -2.25);
  EXPECT_EQ(back.pose_.covariance_[35], 17.5);
  EXPECT_EQ(back.twist_.twist_.linear_.x_, 3.0);
  dds_sample_free(&back, TypeDescriptor<msg::Odometry>::get(), DDS_FREE_CONTENTS);
}

TEST_F(TapTest, OccupancyGridBytesAreWhatDdsDeliversAndReadBack) {
  Participant participant(static_cast<dds_domainid_t>(test_domain()));
  const std::string ns = unique_ns("tapgrid");
  const Qos qos = topic_qos(SemapTopic::kCostmap);
  Topic<msg::OccupancyGrid> topic(participant, topic_name(ns, SemapTopic::kCostmap), qos);
  Reader<msg::OccupancyGrid> reader(participant, topic, qos);
  Writer<msg::OccupancyGrid> writer(participant, topic, qos);
  RecordingTap tap;
  writer.attach_tap(tap);
  EXPECT_EQ(tap.channels[0].type, "nav_msgs/msg/OccupancyGrid");
  EXPECT_TRUE(tap.channels[0].latched);  // transient local

  // Odd sizes: the body's padding to 4 bytes shows in the encapsulation options.
  std::vector<std::uint8_t> cells(7 * 5 + 2);
  for (std::size_t i = 0; i < cells.size(); ++i) cells[i] = static_cast<std::uint8_t>(i * 7);
  msg::OccupancyGrid g{};
  g.header_.frame_id_ = const_cast<char*>("map");
  g.info_.resolution_ = 0.2f;
  g.info_.width_ = 7;
  g.info_.height_ = 5;
  g.info_.origin_.position_.x_ = -4.0;
  g.info_.origin_.orientation_.w_ = 1.0;
  g.data_ = borrow_sequence<dds_sequence_octet>(cells.data(), cells.size());
  ASSERT_TRUE(writer.wait_for_readers(1, std::chrono::milliseconds(5000)));
  writer.write(g);

  const auto dds_bytes = received_cdr(reader);
  ASSERT_FALSE(dds_bytes.empty());
  ASSERT_EQ(tap.messages.size(), 1u);
  EXPECT_EQ(tap.messages[0].second, dds_bytes);

  msg::OccupancyGrid back{};
  ASSERT_TRUE(deserialize_cdr(std::span<const std::uint8_t>(tap.messages[0].second), back));
  EXPECT_EQ(back.info_.width_, 7u);
  EXPECT_EQ(back.info_.height_, 5u);
  EXPECT_FLOAT_EQ(back.info_.resolution_, 0.2f);
  EXPECT_EQ(back.info_.origin_.position_.x_, -4.0);
  ASSERT_EQ(back.data_._length, cells.size());
  EXPECT_EQ(std::vector<std::uint8_t>(back.data_._buffer, back.data_._buffer + back.data_._length),
            cells);
  dds_sample_free(&back, TypeDescriptor<msg::OccupancyGrid>::get(), DDS_FREE_CONTENTS);
}

TEST_F(TapTest, WithoutATapNothingIsSerialisedTwice) {
  Participant participant(static_cast<dds_domainid_t>(test_domain()));
  const Qos qos = topic_qos(SemapTopic::kHealth);
  Topic<msg::Health> topic(participant, topic_name(unique_ns("notap"), SemapTopic::kHealth), qos);
  Writer<msg::Health> writer(participant, topic, qos);
  EXPECT_FALSE(writer.tapped());
}

}  // namespace
}  // namespace semap::dds_idl::testing
