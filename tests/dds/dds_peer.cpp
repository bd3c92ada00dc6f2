// The other process of the dds tests: publishes or listens on loopback as told by its flags and
// reports on stdout, one line per event, so the test can follow it.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <thread>

#include "semap/dds_idl/block_codec.hpp"
#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/health.hpp"
#include "semap/dds_idl/map_client.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/dds_idl/topic_names.hpp"
#include "test_blocks.hpp"

namespace sd = semap::dds_idl;
using semap::common::Stamp;
using std::chrono::milliseconds;

namespace {

struct Options {
  std::string role;
  int domain = 0;
  std::string ns;
  int blocks = 100;
  int classes = 5;
  int version = 1;
  bool evidence = false;
  double seconds = 20.0;
  std::string security_dir;
  std::string identity;
  std::string plugin_dir;
};

sd::Qos participant_qos(const Options& o) {
  sd::Qos q;
  if (!o.security_dir.empty()) {
    q.security(sd::SecurityConfig::from_directory(o.plugin_dir, o.security_dir, o.identity));
  }
  return q;
}

bool time_left(std::chrono::steady_clock::time_point start, const Options& o) {
  return std::chrono::steady_clock::now() - start < std::chrono::duration<double>(o.seconds);
}

sd::MapDescription description(const Options& o) {
  sd::MapDescription d;
  d.resolution = 0.2f;
  d.block_cells = 4;
  d.num_classes = static_cast<std::uint16_t>(o.classes);
  for (int k = 0; k < o.classes; ++k) {
    d.class_names.push_back("class" + std::to_string(k));
    d.class_colors.push_back(0x101010u * static_cast<std::uint32_t>(k));
  }
  return d;
}

int map_pub(const Options& o, const sd::Participant& p) {
  sd::MapPublisherConfig cfg;
  cfg.ns = o.ns;
  cfg.blocks_hz = 10.0;
  cfg.cloud_hz = 1.0;
  sd::SnapshotStore pub_blocks;
  sd::MapPublisher pub(p, cfg, description(o), pub_blocks);
  for (int i = 0; i < o.blocks; ++i) {
    pub.changed(pub_blocks.put(
        sd::testing::make_block(sd::testing::grid_index(i), static_cast<std::uint32_t>(o.version),
                                static_cast<std::uint16_t>(o.classes), o.evidence)));
  }
  const auto start = std::chrono::steady_clock::now();
  std::cout << "published " << pub.publish_changed(Stamp::now()) << std::endl;
  while (time_left(start, o)) {
    pub.spin_once(Stamp::now());
    std::this_thread::sleep_for(milliseconds(20));
  }
  return 0;
}

int map_listen(const Options& o, const sd::Participant& p) {
  sd::MapClient client(p, {o.ns, {}});
  std::cout << "listening" << std::endl;
  const auto start = std::chrono::steady_clock::now();
  std::size_t reported = 0;
  while (time_left(start, o)) {
    client.wait_for_blocks(static_cast<std::size_t>(o.blocks), milliseconds(100));
    int matching = 0;
    for (const auto& [index, b] : client.blocks()) {
      const auto expected =
          sd::testing::make_block(index, static_cast<std::uint32_t>(o.version),
                                  static_cast<std::uint16_t>(o.classes), b.has_evidence());
      matching += sd::testing::same_content(b, expected);
    }
    if (client.blocks().size() != reported) {
      reported = client.blocks().size();
      std::cout << "have " << reported << std::endl;
    }
    if (matching == o.blocks) {
      std::cout << "match " << matching << std::endl;
      return 0;
    }
  }
  std::cout << "timeout" << std::endl;
  return 1;
}

int bad_pub(const Options& o, const sd::Participant& p) {
  sd::Topic<sd::msg::SemanticMapBlock> topic(p, sd::topic_name(o.ns, sd::SemapTopic::kMapBlocks));
  sd::Writer<sd::msg::SemanticMapBlock> writer(p, topic, sd::topic_qos(sd::SemapTopic::kMapBlocks));
  const auto classes = static_cast<std::uint16_t>(o.classes);
  auto write = [&](const sd::BlockSnapshot& b) {
    const sd::BlockMessage m(b, Stamp::now(), "map");
    writer.write(m.get());
  };
  // Distinct keys, so keep-last-1 per instance keeps every one of them.
  write(sd::testing::make_block({0, 0, 0}, 1, classes, true));
  write(sd::testing::make_block({1, 0, 0}, 1, static_cast<std::uint16_t>(classes + 2), false));
  auto nan_block = sd::testing::make_block({2, 0, 0}, 1, classes, false);
  nan_block.variance[5] = std::numeric_limits<float>::quiet_NaN();
  write(nan_block);
  write(sd::testing::make_block({1 << 22, 0, 0}, 1, classes, false));
  auto bad_state = sd::testing::make_block({3, 0, 0}, 1, classes, false);
  bad_state.state[2] = static_cast<semap::common::CellState>(7);
  write(bad_state);
  auto bad_class = sd::testing::make_block({4, 0, 0}, 1, classes, false);
  bad_class.argmax_class[1] = classes;
  write(bad_class);
  auto short_block = sd::testing::make_block({5, 0, 0}, 1, classes, false);
  short_block.variance.pop_back();
  write(short_block);
  auto inf_evidence = sd::testing::make_block({6, 0, 0}, 1, classes, true);
  inf_evidence.evidence[3] = std::numeric_limits<float>::infinity();
  write(inf_evidence);
  write(sd::testing::make_block({7, 0, 0}, 1, classes, false));
  std::cout << "published 9" << std::endl;
  const auto start = std::chrono::steady_clock::now();
  while (time_left(start, o)) std::this_thread::sleep_for(milliseconds(50));
  return 0;
}

// Every standard type with values the test knows, at 20 Hz.
int types_pub(const Options& o, const sd::Participant& p) {
  using sd::SemapTopic;
  auto topic_of = [&](SemapTopic t) { return sd::topic_name(o.ns, t); };
  sd::Topic<sd::msg::Imu> imu_t(p, topic_of(SemapTopic::kImu));
  sd::Writer<sd::msg::Imu> imu_w(p, imu_t, sd::topic_qos(SemapTopic::kImu));
  sd::Topic<sd::msg::NavSatFix> gnss_t(p, topic_of(SemapTopic::kGnss));
  sd::Writer<sd::msg::NavSatFix> gnss_w(p, gnss_t, sd::topic_qos(SemapTopic::kGnss));
  sd::Topic<sd::msg::Odometry> odom_t(p, topic_of(SemapTopic::kOdometry));
  sd::Writer<sd::msg::Odometry> odom_w(p, odom_t, sd::topic_qos(SemapTopic::kOdometry));
  sd::Topic<sd::msg::PoseWithCovarianceStamped> pose_t(p, topic_of(SemapTopic::kPose));
  sd::Writer<sd::msg::PoseWithCovarianceStamped> pose_w(p, pose_t,
                                                        sd::topic_qos(SemapTopic::kPose));
  sd::Topic<sd::msg::Health> health_t(p, topic_of(SemapTopic::kHealth));
  sd::Writer<sd::msg::Health> health_w(p, health_t, sd::topic_qos(SemapTopic::kHealth));
  sd::MapPublisherConfig cfg;
  cfg.ns = o.ns;
  cfg.cloud_hz = 20.0;
  sd::SnapshotStore map_blocks;
  sd::MapPublisher map(p, cfg, description(o), map_blocks);
  map.changed(map_blocks.put(
      sd::testing::make_block({0, 0, 0}, 1, static_cast<std::uint16_t>(o.classes), false)));

  const std::string frame = "map";
  const std::string imu_frame = "imu";
  const std::string base = "base_link";
  semap::common::ImuSample imu;
  imu.gyro = {0.1, 0.2, 0.3};
  imu.accel = {0.0, 0.0, 9.81};
  semap::common::GnssFix fix;
  fix.latitude_deg = 52.1;
  fix.longitude_deg = 4.3;
  fix.altitude_m = 12.5;
  fix.quality = semap::common::FixQuality::kRtkFixed;
  sd::PoseEstimate pose;
  pose.position = {1.0, 2.0, 3.0};
  pose.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
  pose.velocity_body = {0.5, 0.0, 0.0};
  sd::HealthReport report;
  report.stages.push_back({"mapping", 9.5f, 3, 2, 1.5f, 4.0f});
  report.drivers.push_back({"can_imu", 4000, 1, 0, 0});

  const auto start = std::chrono::steady_clock::now();
  std::uint64_t n = 0;
  while (time_left(start, o)) {
    const Stamp now = Stamp::now();
    imu.stamp = fix.stamp = pose.stamp = now;
    sd::msg::Imu imu_m;
    sd::to_msg(imu, imu_frame, 1e-4, 1e-2, imu_m);
    imu_w.write(imu_m);
    sd::msg::NavSatFix fix_m;
    sd::to_msg(fix, imu_frame, fix_m);
    gnss_w.write(fix_m);
    sd::msg::Odometry odom_m;
    sd::to_msg(pose, frame, base, odom_m);
    odom_w.write(odom_m);
    sd::msg::PoseWithCovarianceStamped pose_m;
    sd::to_msg(pose, frame, pose_m);
    pose_w.write(pose_m);
    report.stamp = now;
    const sd::HealthMessage health(report, base);
    health_w.write(health.get());
    map.spin_once(now);
    if (++n == 1) std::cout << "publishing" << std::endl;
    std::this_thread::sleep_for(milliseconds(50));
  }
  return 0;
}

int pose_pub(const Options& o, const sd::Participant& p) {
  std::uint64_t written = 0;
  try {
    sd::Topic<sd::msg::PoseWithCovarianceStamped> t(p, sd::topic_name(o.ns, sd::SemapTopic::kPose));
    sd::Writer<sd::msg::PoseWithCovarianceStamped> w(p, t, sd::topic_qos(sd::SemapTopic::kPose));
    std::cout << "writer ok" << std::endl;
    const std::string frame = "map";
    sd::PoseEstimate pose;
    pose.position = {7.0, 7.0, 7.0};
    const auto start = std::chrono::steady_clock::now();
    while (time_left(start, o)) {
      pose.stamp = Stamp::now();
      sd::msg::PoseWithCovarianceStamped m;
      sd::to_msg(pose, frame, m);
      w.write(m);
      ++written;
      std::this_thread::sleep_for(milliseconds(20));
    }
  } catch (const sd::DdsError& e) {
    std::cout << "writer failed: " << e.what() << std::endl;
    return 2;
  }
  std::cout << "written " << written << std::endl;
  return 0;
}

int pose_listen(const Options& o, const sd::Participant& p) {
  std::uint64_t received = 0;
  try {
    sd::Topic<sd::msg::PoseWithCovarianceStamped> t(p, sd::topic_name(o.ns, sd::SemapTopic::kPose));
    sd::Reader<sd::msg::PoseWithCovarianceStamped> r(p, t, sd::topic_qos(sd::SemapTopic::kPose));
    std::cout << "reader ok" << std::endl;
    const auto start = std::chrono::steady_clock::now();
    while (time_left(start, o)) {
      r.wait(milliseconds(50));
      received += r.take_each([](const auto&, const auto&) {});
    }
  } catch (const sd::DdsError& e) {
    std::cout << "reader failed: " << e.what() << std::endl;
    return 2;
  }
  std::cout << "received " << received << std::endl;
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("dds test peer");
  Options o;
  app.add_option("role", o.role)
      ->required()
      ->check(CLI::IsMember(
          {"map-pub", "map-listen", "bad-pub", "types-pub", "pose-pub", "pose-listen"}));
  app.add_option("--domain", o.domain)->required();
  app.add_option("--ns", o.ns);
  app.add_option("--blocks", o.blocks);
  app.add_option("--classes", o.classes);
  app.add_option("--version", o.version);
  app.add_flag("--evidence", o.evidence);
  app.add_option("--seconds", o.seconds);
  app.add_option("--security", o.security_dir);
  app.add_option("--identity", o.identity);
  app.add_option("--plugins", o.plugin_dir);
  CLI11_PARSE(app, argc, argv);
  try {
    sd::Participant p(static_cast<dds_domainid_t>(o.domain), participant_qos(o));
    if (o.role == "map-pub") return map_pub(o, p);
    if (o.role == "map-listen") return map_listen(o, p);
    if (o.role == "bad-pub") return bad_pub(o, p);
    if (o.role == "types-pub") return types_pub(o, p);
    if (o.role == "pose-pub") return pose_pub(o, p);
    return pose_listen(o, p);
  } catch (const std::exception& e) {
    std::cout << "error: " << e.what() << std::endl;
    return 3;
  }
}
