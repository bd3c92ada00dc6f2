#include "dds_outputs.hpp"

#include <chrono>

#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/topic_names.hpp"

namespace semap::onboard {

DdsOutputs::DdsOutputs(const OnboardConfig& config, const dds_idl::BlockSource& map_blocks)
    : config_(config),
      participant_(static_cast<dds_domainid_t>(config.dds.domain)),
      odometry_topic_(participant_,
                      dds_idl::topic_name(config.dds.ns, dds_idl::SemapTopic::kOdometry),
                      dds_idl::topic_qos(dds_idl::SemapTopic::kOdometry)),
      odometry_writer_(participant_, odometry_topic_,
                       dds_idl::topic_qos(dds_idl::SemapTopic::kOdometry)),
      health_topic_(participant_, dds_idl::topic_name(config.dds.ns, dds_idl::SemapTopic::kHealth),
                    dds_idl::topic_qos(dds_idl::SemapTopic::kHealth)),
      health_writer_(participant_, health_topic_, dds_idl::topic_qos(dds_idl::SemapTopic::kHealth)),
      map_publisher_(participant_,
                     dds_idl::MapPublisherConfig{config.dds.ns, config.dds.frame_id,
                                                 config.dds.publish_hz, config.dds.cloud_hz},
                     describe_map(config), map_blocks) {}

DdsOutputs::~DdsOutputs() { stop(); }

void DdsOutputs::start() {
  publisher_thread_ = std::jthread([this](std::stop_token stop) { run_publisher(stop); });
}

void DdsOutputs::stop() {
  if (!publisher_thread_.joinable()) return;
  publisher_thread_.request_stop();
  publisher_thread_.join();
  // The last changes go out now rather than at the next round.
  take_changed();
  map_publisher_.publish_changed(common::Stamp::now());
  update_counters();
}

void DdsOutputs::blocks_changed(const std::vector<common::BlockIndex>& blocks) {
  std::lock_guard lock(changed_mutex_);
  changed_.insert(blocks.begin(), blocks.end());
}

void DdsOutputs::take_changed() {
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> changed;
  {
    std::lock_guard lock(changed_mutex_);
    changed.swap(changed_);
  }
  for (const auto& index : changed) map_publisher_.changed(index);
}

void DdsOutputs::update_counters() {
  std::lock_guard lock(map_counters_mutex_);
  map_counters_ = map_publisher_.counters();
  map_pending_ = map_publisher_.pending();
}

void DdsOutputs::run_publisher(std::stop_token stop) {
  // Rounds are due at the publisher's rates; this only bounds how late one starts.
  constexpr auto kTick = std::chrono::milliseconds(20);
  while (!stop.stop_requested()) {
    take_changed();
    map_publisher_.spin_once(common::Stamp::now());
    update_counters();
    std::this_thread::sleep_for(kTick);
  }
}

void DdsOutputs::publish_pose(const PoseOutput& pose) {
  dds_idl::PoseEstimate p;
  p.stamp = pose.pose.stamp;
  p.position = pose.pose.position;
  p.orientation = pose.pose.orientation;
  p.velocity_body = pose.pose.orientation.conjugate() * pose.pose.velocity;
  p.angular_velocity_body = pose.angular_velocity_body;
  p.pose_covariance.setZero();
  p.pose_covariance.topLeftCorner<3, 3>() = pose.position_covariance;
  p.pose_covariance.bottomRightCorner<3, 3>() = pose.rotation_covariance;
  dds_idl::msg::Odometry msg{};
  const std::string child = "base_link";
  dds_idl::to_msg(p, config_.dds.frame_id, child, msg);
  odometry_writer_.write(msg);
  odometry_written_.fetch_add(1);
}

void DdsOutputs::publish_health(const dds_idl::HealthReport& report) {
  const dds_idl::HealthMessage m(report, config_.dds.frame_id);
  health_writer_.write(m.get());
  ++health_written_;
}

std::size_t DdsOutputs::map_pending() const {
  std::lock_guard lock(map_counters_mutex_);
  return map_pending_;
}

dds_idl::MapPublisherCounters DdsOutputs::map_counters() const {
  std::lock_guard lock(map_counters_mutex_);
  return map_counters_;
}

}  // namespace semap::onboard
