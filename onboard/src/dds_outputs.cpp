#include "semap/onboard/dds_outputs.hpp"

#include <chrono>

#include "semap/dds_idl/converters.hpp"
#include "semap/dds_idl/topic_names.hpp"

namespace semap::onboard {

DdsOutputs::DdsOutputs(const DdsConfig& config, const dds_idl::MapDescription& map,
                       const dds_idl::BlockSource& map_blocks,
                       const std::vector<SensorFrame>& sensor_frames,
                       const std::optional<CostmapConfig>& costmap, const CostmapSource* costmaps)
    : config_(config),
      participant_(static_cast<dds_domainid_t>(config.domain)),
      odometry_topic_(
          participant_, dds_idl::topic_name(config.ns, dds_idl::SemapTopic::kOdometry),
          dds_idl::topic_qos(dds_idl::SemapTopic::kOdometry, config.sensor_reliability)),
      odometry_writer_(
          participant_, odometry_topic_,
          dds_idl::topic_qos(dds_idl::SemapTopic::kOdometry, config.sensor_reliability)),
      gnss_topic_(participant_, dds_idl::topic_name(config.ns, dds_idl::SemapTopic::kGnss),
                  dds_idl::topic_qos(dds_idl::SemapTopic::kGnss, config.sensor_reliability)),
      gnss_writer_(participant_, gnss_topic_,
                   dds_idl::topic_qos(dds_idl::SemapTopic::kGnss, config.sensor_reliability)),
      tf_topic_(participant_, dds_idl::topic_name(config.ns, dds_idl::SemapTopic::kTf),
                dds_idl::topic_qos(dds_idl::SemapTopic::kTf)),
      tf_writer_(participant_, tf_topic_, dds_idl::topic_qos(dds_idl::SemapTopic::kTf)),
      tf_static_topic_(participant_, dds_idl::topic_name(config.ns, dds_idl::SemapTopic::kTfStatic),
                       dds_idl::topic_qos(dds_idl::SemapTopic::kTfStatic)),
      tf_static_writer_(participant_, tf_static_topic_,
                        dds_idl::topic_qos(dds_idl::SemapTopic::kTfStatic)),
      health_topic_(participant_, dds_idl::topic_name(config.ns, dds_idl::SemapTopic::kHealth),
                    dds_idl::topic_qos(dds_idl::SemapTopic::kHealth)),
      health_writer_(participant_, health_topic_, dds_idl::topic_qos(dds_idl::SemapTopic::kHealth)),
      map_publisher_(participant_,
                     dds_idl::MapPublisherConfig{config.ns, config.frame_id, config.publish_hz,
                                                 config.cloud_hz},
                     map, map_blocks),
      sensor_frames_(sensor_frames) {
  dds_idl::set_stamp_clock(config.stamp_clock);
  write_tf_static();
  if (costmap && costmaps != nullptr) {
    costmap_.emplace(participant_, config.ns, config.frame_id, *costmap, *costmaps);
  }
}

void DdsOutputs::write_tf_static() {
  if (sensor_frames_.empty()) return;
  const common::Stamp now = common::Stamp::now();
  std::vector<dds_idl::msg::TransformStamped> transforms(sensor_frames_.size());
  for (std::size_t i = 0; i < sensor_frames_.size(); ++i) {
    dds_idl::to_msg(sensor_frames_[i].body_from_sensor, now, config_.base_frame_id,
                    sensor_frames_[i].name, transforms[i]);
  }
  dds_idl::msg::TFMessage m{};
  m.transforms_ = dds_idl::borrow_sequence<dds_sequence_geometry_msgs_msg_dds__TransformStamped_>(
      transforms.data(), transforms.size());
  tf_static_writer_.write(m);
}

void DdsOutputs::attach_tap(dds_idl::MessageTap& tap) {
  odometry_writer_.attach_tap(tap);
  gnss_writer_.attach_tap(tap);
  tf_writer_.attach_tap(tap);
  tf_static_writer_.attach_tap(tap);
  health_writer_.attach_tap(tap);
  map_publisher_.attach_tap(tap);
  if (costmap_) costmap_->attach_tap(tap);
  write_tf_static();  // the tap's copy (a DDS reader gets the same transforms again)
}

// Only joins: the map view may be gone by now (stop() is what publishes the last changes).
DdsOutputs::~DdsOutputs() { publisher_stage_.stop(); }

void DdsOutputs::start(std::vector<int> cpus) {
  publisher_stage_.start([this](std::stop_token stop) { run_publisher(stop); }, "dds",
                         std::move(cpus));
}

void DdsOutputs::stop() {
  if (!publisher_stage_.stop()) return;
  // The last changes go out now rather than at the next round.
  take_changed();
  map_publisher_.publish_changed(common::Stamp::now());
  update_counters();
}

void DdsOutputs::blocks_changed(const std::vector<common::BlockIndex>& updated,
                                const std::vector<common::BlockIndex>& paged_out) {
  std::lock_guard lock(changed_mutex_);
  changed_.insert(updated.begin(), updated.end());
  paged_out_.insert(paged_out.begin(), paged_out.end());
}

void DdsOutputs::take_changed() {
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> changed, paged_out;
  {
    std::lock_guard lock(changed_mutex_);
    changed.swap(changed_);
    paged_out.swap(paged_out_);
  }
  for (const auto& index : changed) {
    map_publisher_.changed(index);
    if (costmap_) costmap_->changed(index);
  }
  for (const auto& index : paged_out) map_publisher_.forget(index);
}

void DdsOutputs::update_counters() {
  publisher_stage_.figures() = {map_publisher_.counters(), map_publisher_.pending()};
  publisher_stage_.share();
}

void DdsOutputs::run_publisher(std::stop_token stop) {
  // Rounds are due at the publisher's rates; this only bounds how late one starts.
  constexpr auto kTick = std::chrono::milliseconds(20);
  while (!stop.stop_requested()) {
    take_changed();
    const common::Stamp now = common::Stamp::now();
    // What planners wait for first (the cloud's and the costmap's changes), the map blocks,
    // which take longest to write, last.
    map_publisher_.spin_updates(now);
    if (costmap_) {
      std::optional<Eigen::Vector2d> robot;
      {
        std::lock_guard lock(robot_mutex_);
        robot = robot_;
      }
      costmap_->spin_once(now, robot);
    }
    map_publisher_.spin_once(now);
    update_counters();
    std::this_thread::sleep_for(kTick);
  }
}

void DdsOutputs::publish_fix(const common::GnssFix& fix) {
  // The message borrows the frame id's characters until it is written.
  static const std::string kGnssFrameId = "gnss";
  dds_idl::msg::NavSatFix m;
  dds_idl::to_msg(fix, kGnssFrameId, m);
  gnss_writer_.write(m);
}

void DdsOutputs::publish_pose(const PoseOutput& pose) {
  if (costmap_) {
    std::lock_guard lock(robot_mutex_);
    robot_ = pose.pose.position.head<2>();
  }
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
  dds_idl::to_msg(p, config_.frame_id, config_.base_frame_id, msg);
  odometry_writer_.write(msg);
  // TF's map -> base_link at the odometry rate, so RViz places the cloud and the costmap.
  Eigen::Isometry3d map_from_base = Eigen::Isometry3d::Identity();
  map_from_base.linear() = pose.pose.orientation.toRotationMatrix();
  map_from_base.translation() = pose.pose.position;
  dds_idl::msg::TransformStamped transform;
  dds_idl::to_msg(map_from_base, p.stamp, config_.frame_id, config_.base_frame_id, transform);
  dds_idl::msg::TFMessage tf{};
  tf.transforms_ = dds_idl::borrow_sequence<dds_sequence_geometry_msgs_msg_dds__TransformStamped_>(
      &transform, 1);
  tf_writer_.write(tf);
  odometry_written_.fetch_add(1);
}

void DdsOutputs::publish_health(const dds_idl::HealthReport& report) {
  const dds_idl::HealthMessage m(report, config_.frame_id);
  health_writer_.write(m.get());
  ++health_written_;
}

std::size_t DdsOutputs::map_pending() const { return publisher_stage_.stats().pending; }

dds_idl::MapPublisherCounters DdsOutputs::map_counters() const {
  return publisher_stage_.stats().counters;
}

}  // namespace semap::onboard
