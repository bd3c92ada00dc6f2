// ROS 2 interop as far as this machine can check it without ROS 2: what semap's writers
// announce in DDS discovery (SEDP), read back by another process through Cyclone's built-in
// DCPSPublication topic, which is where a ROS 2 node using rmw_cyclonedds_cpp learns about
// them too. Each topic and type name must be exactly the one rosidl/rmw would use, and the
// reliability and durability (the QoS that decide matching) those documented in docs/dds.md.
// rmw_cyclonedds creates every reader keyless, and Cyclone matches a keyless reader only with a
// keyless writer: every topic a ROS 2 node reads must come from a keyless writer (the entity
// kind in the writer's GUID says which); only map_blocks, for DDS-native clients, is keyed.
#include <dds/dds.h>
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <thread>

#include "dds_fixture.hpp"
#include "semap/dds_idl/entity.hpp"
#include "semap/dds_idl/participant.hpp"

namespace semap::dds_idl::testing {
namespace {

struct Announced {
  std::string type;
  dds_reliability_kind_t reliability = DDS_RELIABILITY_BEST_EFFORT;
  dds_durability_kind_t durability = DDS_DURABILITY_VOLATILE;
  bool has_history = false;
  dds_history_kind_t history = DDS_HISTORY_KEEP_LAST;
  std::int32_t depth = 0;
  bool keyed = false;
};

struct Expected {
  std::string leaf;      // rt/<ns>/semap/<leaf>
  std::string dds_type;  // as rosidl_generator_dds_idl names it
  std::string ros_type;  // what `ros2 topic list -t` shows
  dds_reliability_kind_t reliability;
  dds_durability_kind_t durability;
  std::int32_t depth;
  bool keyed = false;
};

const std::vector<Expected>& expected_topics() {
  static const std::vector<Expected> topics{
      {"odometry", "nav_msgs::msg::dds_::Odometry_", "nav_msgs/msg/Odometry",
       DDS_RELIABILITY_BEST_EFFORT, DDS_DURABILITY_VOLATILE, 1},
      {"pose", "geometry_msgs::msg::dds_::PoseWithCovarianceStamped_",
       "geometry_msgs/msg/PoseWithCovarianceStamped", DDS_RELIABILITY_RELIABLE,
       DDS_DURABILITY_VOLATILE, 1},
      {"gnss", "sensor_msgs::msg::dds_::NavSatFix_", "sensor_msgs/msg/NavSatFix",
       DDS_RELIABILITY_BEST_EFFORT, DDS_DURABILITY_VOLATILE, 10},
      {"imu", "sensor_msgs::msg::dds_::Imu_", "sensor_msgs/msg/Imu", DDS_RELIABILITY_BEST_EFFORT,
       DDS_DURABILITY_VOLATILE, 10},
      {"map_cloud", "sensor_msgs::msg::dds_::PointCloud2_", "sensor_msgs/msg/PointCloud2",
       DDS_RELIABILITY_RELIABLE, DDS_DURABILITY_TRANSIENT_LOCAL, 1},
      {"map_cloud_updates", "sensor_msgs::msg::dds_::PointCloud2_", "sensor_msgs/msg/PointCloud2",
       DDS_RELIABILITY_RELIABLE, DDS_DURABILITY_VOLATILE, 10},
      {"map_blocks", "semap_msgs::msg::dds_::SemanticMapBlock_", "semap_msgs/msg/SemanticMapBlock",
       DDS_RELIABILITY_RELIABLE, DDS_DURABILITY_TRANSIENT_LOCAL, 1, true},
      {"map_info", "semap_msgs::msg::dds_::MapInfo_", "semap_msgs/msg/MapInfo",
       DDS_RELIABILITY_RELIABLE, DDS_DURABILITY_TRANSIENT_LOCAL, 1},
      {"health", "semap_msgs::msg::dds_::Health_", "semap_msgs/msg/Health",
       DDS_RELIABILITY_RELIABLE, DDS_DURABILITY_VOLATILE, 10},
  };
  return topics;
}

// rmw_cyclonedds_cpp's demangling: "rt/a/b" -> "/a/b" and "pkg::msg::dds_::Name_" ->
// "pkg/msg/Name"; anything else is not a ROS 2 topic and stays hidden from ROS tools.
std::string ros_topic(const std::string& dds) {
  return dds.rfind("rt/", 0) == 0 ? dds.substr(2) : "";
}
std::string ros_type(const std::string& dds) {
  const std::string marker = "::dds_::";
  const auto at = dds.find(marker);
  if (at == std::string::npos || dds.empty() || dds.back() != '_') return "";
  std::string pkg_msg = dds.substr(0, at);
  for (std::size_t p; (p = pkg_msg.find("::")) != std::string::npos;) pkg_msg.replace(p, 2, "/");
  return pkg_msg + "/" + dds.substr(at + marker.size(), dds.size() - at - marker.size() - 1);
}

// The publications discovered on topics under `prefix`, collected until `count` are known
// or the timeout passes.
std::map<std::string, Announced> discovered_publications(const Participant& participant,
                                                         const std::string& prefix,
                                                         std::size_t count,
                                                         std::chrono::milliseconds timeout) {
  const Entity reader(
      dds_create_reader(participant.handle(), DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr));
  EXPECT_GT(reader.handle(), 0) << dds_strretcode(reader.handle());
  std::map<std::string, Announced> out;
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (out.size() < count && std::chrono::steady_clock::now() < deadline) {
    void* samples[32] = {};
    dds_sample_info_t infos[32];
    const dds_return_t n = dds_take(reader.handle(), samples, infos, 32, 32);
    for (dds_return_t i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      const auto* ep = static_cast<const dds_builtintopic_endpoint_t*>(samples[i]);
      const std::string topic = ep->topic_name;
      if (topic.rfind(prefix, 0) != 0) continue;
      Announced a;
      a.type = ep->type_name;
      dds_duration_t blocking = 0;
      dds_qget_reliability(ep->qos, &a.reliability, &blocking);
      dds_qget_durability(ep->qos, &a.durability);
      a.has_history = dds_qget_history(ep->qos, &a.history, &a.depth);
      // RTPS entity kinds: 0x02 user writer with key, 0x03 without.
      a.keyed = ep->key.v[15] == 0x02;
      out[topic] = a;
    }
    if (n > 0) dds_return_loan(reader.handle(), samples, n);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return out;
}

TEST_F(DdsTest, WritersAnnounceRos2TopicAndTypeNames) {
  const std::string ns = unique_ns("ros2");
  // Another process writes every topic, as the robot would.
  ChildProcess pub(peer("types-pub", {"--ns", ns, "--classes", "4", "--seconds", "20"}));
  ASSERT_TRUE(pub.expect("publishing", seconds(10)));

  const Participant participant(test_domain());
  const std::string prefix = "rt/" + ns + "/semap/";
  const auto found =
      discovered_publications(participant, prefix, expected_topics().size() + 1, seconds(3));
  // Exactly the expected topics: none missing, none extra (same leaf on another type, or a
  // topic without the rt/ prefix, would show up here or be missing).
  ASSERT_EQ(found.size(), expected_topics().size());
  for (const Expected& e : expected_topics()) {
    const std::string topic = prefix + e.leaf;
    SCOPED_TRACE(topic);
    const auto it = found.find(topic);
    ASSERT_NE(it, found.end());
    const Announced& a = it->second;
    EXPECT_EQ(a.type, e.dds_type);
    EXPECT_EQ(ros_topic(topic), "/" + ns + "/semap/" + e.leaf);
    EXPECT_EQ(ros_type(a.type), e.ros_type);
    EXPECT_EQ(a.reliability, e.reliability);
    EXPECT_EQ(a.durability, e.durability);
    EXPECT_EQ(a.keyed, e.keyed) << "a keyed writer never matches rmw_cyclonedds' keyless readers";
    // Cyclone announces the history too (not an RxO policy, but the documented depth).
    ASSERT_TRUE(a.has_history);
    EXPECT_EQ(a.history, DDS_HISTORY_KEEP_LAST);
    EXPECT_EQ(a.depth, e.depth);
  }
  pub.kill();
}

}  // namespace
}  // namespace semap::dds_idl::testing
