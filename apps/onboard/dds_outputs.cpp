#include "dds_outputs.hpp"

#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/topic_names.hpp"

namespace semap::onboard {

DdsOutputs::DdsOutputs(const OnboardConfig& config)
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
                     describe_map(config)) {}

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

void DdsOutputs::publish_blocks(std::vector<dds_idl::BlockSnapshot>&& blocks, common::Stamp now) {
  for (auto& b : blocks) map_publisher_.update(std::move(b));
  map_publisher_.spin_once(now);
  std::lock_guard lock(map_counters_mutex_);
  map_counters_ = map_publisher_.counters();
  map_pending_ = map_publisher_.pending();
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
