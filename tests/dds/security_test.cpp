// DDS Security across processes with the test PKI of scripts/dds-security: only the robot may
// write, only permitted planners may read, unauthenticated participants see and inject nothing.
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "dds_fixture.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/map_client.hpp"
#include "semap/dds_idl/reader.hpp"
#include "semap/dds_idl/topic_names.hpp"

namespace semap::dds_idl::testing {
namespace {

namespace fs = std::filesystem;

class SecurityTest : public DdsTest {
 protected:
  static void SetUpTestSuite() {
    char tmpl[] = "/tmp/semap-dds-security-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    const std::string cmd =
        std::string(SEMAP_SOURCE_DIR) + "/scripts/dds-security " + dir_.string() + " > /dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static Qos identity(const std::string& name) {
    return std::move(
        Qos().security(SecurityConfig::from_directory(SEMAP_DDS_SECURITY_PLUGIN_DIR, dir_, name)));
  }
  static std::vector<std::string> secured_peer(const std::string& role, const std::string& who,
                                               std::vector<std::string> args) {
    args.insert(args.end(), {"--security", dir_.string(), "--identity", who, "--plugins",
                             SEMAP_DDS_SECURITY_PLUGIN_DIR});
    return peer(role, args);
  }

  // Counts poses arriving at `reader` during `duration`.
  static std::size_t count_poses(Reader<msg::PoseWithCovarianceStamped>& reader,
                                 std::chrono::milliseconds duration) {
    std::size_t n = 0;
    const auto end = std::chrono::steady_clock::now() + duration;
    while (std::chrono::steady_clock::now() < end) {
      reader.wait(milliseconds(50));
      n += reader.take_each([](const auto&, const auto&) {});
    }
    return n;
  }

  static inline fs::path dir_;
};

TEST_F(SecurityTest, PermittedPlannerReceivesPoseAndMap) {
  const std::string ns = unique_ns("secure_ok");
  ChildProcess pose(secured_peer("pose-pub", "robot", {"--ns", ns, "--seconds", "20"}));
  ChildProcess map(
      secured_peer("map-pub", "robot", {"--ns", ns, "--blocks", "50", "--seconds", "20"}));
  ASSERT_TRUE(pose.expect("writer ok", seconds(10)));
  ASSERT_TRUE(map.expect("published 50", seconds(10)));

  Participant planner(test_domain(), identity("planner"));
  Topic<msg::PoseWithCovarianceStamped> topic(planner, topic_name(ns, SemapTopic::kPose));
  Reader<msg::PoseWithCovarianceStamped> reader(planner, topic, topic_qos(SemapTopic::kPose));
  MapClient client(planner, {ns, {}});
  EXPECT_TRUE(client.wait_for_blocks(50, seconds(15))) << client.blocks().size();
  EXPECT_GT(count_poses(reader, milliseconds(1000)), 0u);
}

TEST_F(SecurityTest, UnauthenticatedParticipantReceivesNothing) {
  const std::string ns = unique_ns("secure_eavesdrop");
  ChildProcess pose(secured_peer("pose-pub", "robot", {"--ns", ns, "--seconds", "20"}));
  ChildProcess map(
      secured_peer("map-pub", "robot", {"--ns", ns, "--blocks", "50", "--seconds", "20"}));
  ASSERT_TRUE(pose.expect("writer ok", seconds(10)));
  ASSERT_TRUE(map.expect("published 50", seconds(10)));
  // Control: a permitted planner in another process does receive in the same period.
  ChildProcess planner(secured_peer("pose-listen", "planner", {"--ns", ns, "--seconds", "8"}));

  Participant eavesdropper(test_domain());
  Topic<msg::PoseWithCovarianceStamped> topic(eavesdropper, topic_name(ns, SemapTopic::kPose));
  Reader<msg::PoseWithCovarianceStamped> reader(eavesdropper, topic, topic_qos(SemapTopic::kPose));
  MapClient client(eavesdropper, {ns, {}});
  EXPECT_EQ(count_poses(reader, milliseconds(2500)), 0u);
  EXPECT_FALSE(client.wait_for_blocks(1, milliseconds(500)));
  EXPECT_EQ(client.counters().accepted + client.counters().rejected_total(), 0u);

  const auto received = planner.expect("received", seconds(20));
  ASSERT_TRUE(received);
  EXPECT_NE(*received, "received 0");
}

TEST_F(SecurityTest, UnauthenticatedParticipantCannotInjectPose) {
  const std::string ns = unique_ns("secure_inject");
  ChildProcess intruder(peer("pose-pub", {"--ns", ns, "--seconds", "20"}));
  ASSERT_TRUE(intruder.expect("writer ok", seconds(10)));

  Participant planner(test_domain(), identity("planner"));
  Topic<msg::PoseWithCovarianceStamped> topic(planner, topic_name(ns, SemapTopic::kPose));
  Reader<msg::PoseWithCovarianceStamped> reader(planner, topic, topic_qos(SemapTopic::kPose));
  EXPECT_EQ(count_poses(reader, milliseconds(2500)), 0u);
  EXPECT_EQ(reader.matched(), 0u);
}

TEST_F(SecurityTest, OnlyTheRobotMayWriteAndUnlistedIdentitiesMayNotJoin) {
  const std::string ns = unique_ns("secure_roles");
  ChildProcess planner(secured_peer("pose-pub", "planner", {"--ns", ns, "--seconds", "5"}));
  const auto p = planner.read_line(seconds(10));
  ASSERT_TRUE(p);
  EXPECT_NE(p->find("writer failed"), std::string::npos) << *p;
  EXPECT_NE(p->find("Not Allowed By Security"), std::string::npos) << *p;

  ChildProcess intruder(secured_peer("pose-pub", "intruder", {"--ns", ns, "--seconds", "5"}));
  const auto i = intruder.read_line(seconds(10));
  ASSERT_TRUE(i);
  EXPECT_NE(i->find("error: dds_create_participant"), std::string::npos) << *i;

  EXPECT_THROW(Participant(test_domain(), identity("intruder")), DdsError);
}

// Processes that cannot set security QoS (ros2 CLI, ddsperf) use config/cyclonedds-secure.xml
// with the identity in environment variables; the rights are the same.
TEST_F(SecurityTest, SecuredXmlConfigurationGivesTheSameRights) {
  const std::string ns = unique_ns("secure_xml");
  ChildProcess robot(secured_peer("pose-pub", "robot", {"--ns", ns, "--seconds", "20"}));
  ASSERT_TRUE(robot.expect("writer ok", seconds(10)));
  const auto env = [](const std::string& who) {
    return std::vector<std::string>{
        "CYCLONEDDS_URI=file://" + std::string(SEMAP_SOURCE_DIR) + "/config/cyclonedds-secure.xml",
        "SEMAP_DDS_SECURITY_DIR=" + dir_.string(), "SEMAP_DDS_IDENTITY=" + who,
        "SEMAP_DDS_SECURITY_PLUGINS=" + std::string(SEMAP_DDS_SECURITY_PLUGIN_DIR)};
  };
  ChildProcess planner(peer("pose-listen", {"--ns", ns, "--seconds", "8"}), env("planner"));
  ChildProcess intruder(peer("pose-listen", {"--ns", ns, "--seconds", "2"}), env("intruder"));
  const auto received = planner.expect("received", seconds(20));
  ASSERT_TRUE(received);
  EXPECT_NE(*received, "received 0");
  EXPECT_TRUE(intruder.expect("error: dds_create_participant", seconds(10)));
}

}  // namespace
}  // namespace semap::dds_idl::testing
