#pragma once

#include <memory>
#include <mutex>
#include <thread>
#include <unordered_set>
#include <vector>

#include "semap/dds_idl/health.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/dds_idl/participant.hpp"
#include "semap/dds_idl/topic.hpp"
#include "semap/dds_idl/types.hpp"
#include "semap/dds_idl/writer.hpp"
#include "semap/onboard/estimation_stage.hpp"
#include "semap/onboard/mapping_stage.hpp"
#include "semap/onboard/onboard_config.hpp"
#include "semap/onboard/stage_thread.hpp"

namespace semap::onboard {

// A sensor's frame for TF: its name and where it sits on the robot (body from sensor).
struct SensorFrame {
  std::string name;
  Eigen::Isometry3d body_from_sensor = Eigen::Isometry3d::Identity();
};

// The robot's DDS side: odometry from the estimation stage; map blocks, MapInfo and map_cloud
// from the map publisher's own thread, which reads the blocks the mapping stage says changed
// through its read-only view, at the configured rates, so a slow reader never holds up
// mapping. Each stage calls only its own method, from its own thread.
class DdsOutputs {
 public:
  // `map_blocks` (the mapping stage's view) outlives the publisher thread: stop() first.
  // With `costmap`, also the costmap around the robot, read from `costmaps` (which outlives
  // the publisher thread too).
  // `sensor_frames`: each sensor's frame name and pose in the body frame, published once on
  // tf_static (transient local: a late joiner gets them too).
  DdsOutputs(const DdsConfig& config, const dds_idl::MapDescription& map,
             const dds_idl::BlockSource& map_blocks, const std::vector<SensorFrame>& sensor_frames,
             const std::optional<CostmapConfig>& costmap = std::nullopt,
             const CostmapSource* costmaps = nullptr);
  ~DdsOutputs();

  // The map publisher's thread; stop() publishes what changed last before it returns.
  // `cpus`: the CPUs its thread may run on (realtime.stage_cpus; empty: any).
  void start(std::vector<int> cpus = {});
  void stop();

  void publish_pose(const PoseOutput& pose);
  // Each GNSS fix the estimation stage takes, as sensor_msgs/NavSatFix in the frame "gnss" (the
  // estimation thread).
  void publish_fix(const common::GnssFix& fix);
  // From the mapping thread: these blocks changed, those were paged out to the checkpoint log
  // (cheap, never waits for DDS). A paged-out block leaves the block writer's history once it
  // went out: memory stays bounded by map.memory_radius_m, and a late joiner gets the blocks
  // around the robot rather than the whole map (docs/dds.md).
  void blocks_changed(const std::vector<common::BlockIndex>& updated,
                      const std::vector<common::BlockIndex>& paged_out = {});
  // From the main thread, at 1 Hz.
  void publish_health(const dds_idl::HealthReport& report);
  // Every message written from now on also goes to `tap` as the CDR DDS sends (odometry, gnss, tf,
  // tf_static (written again for it), health, map_info, map_cloud and its updates, the
  // costmap and its updates). Before start(), from the thread that calls start().
  void attach_tap(dds_idl::MessageTap& tap);

  std::uint64_t odometry_written() const { return odometry_written_.load(); }
  std::uint64_t health_written() const { return health_written_; }
  dds_idl::MapPublisherCounters map_counters() const;
  // After stop(): what the costmap output wrote (nullopt without a costmap).
  std::optional<CostmapOutput::Counters> costmap_counters() const {
    return costmap_ ? std::optional(costmap_->counters()) : std::nullopt;
  }
  // Changed blocks waiting for the next publication round.
  std::size_t map_pending() const;

 private:
  const DdsConfig& config_;
  dds_idl::Participant participant_;
  dds_idl::Topic<dds_idl::msg::Odometry> odometry_topic_;
  dds_idl::Writer<dds_idl::msg::Odometry> odometry_writer_;
  std::atomic<std::uint64_t> odometry_written_{0};
  dds_idl::Topic<dds_idl::msg::NavSatFix> gnss_topic_;
  dds_idl::Writer<dds_idl::msg::NavSatFix> gnss_writer_;
  dds_idl::Topic<dds_idl::msg::TFMessage> tf_topic_;
  dds_idl::Writer<dds_idl::msg::TFMessage> tf_writer_;
  dds_idl::Topic<dds_idl::msg::TFMessage> tf_static_topic_;
  dds_idl::Writer<dds_idl::msg::TFMessage> tf_static_writer_;
  dds_idl::Topic<dds_idl::msg::Health> health_topic_;
  dds_idl::Writer<dds_idl::msg::Health> health_writer_;
  void write_tf_static();
  void run_publisher(std::stop_token stop);
  void take_changed();
  void update_counters();

  dds_idl::MapPublisher map_publisher_;   // the publisher thread's
  std::optional<CostmapOutput> costmap_;  // the publisher thread's
  mutable std::mutex robot_mutex_;
  std::optional<Eigen::Vector2d> robot_;  // from the latest pose
  std::mutex changed_mutex_;
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> changed_;
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> paged_out_;
  std::uint64_t health_written_ = 0;  // main thread only
  std::vector<SensorFrame> sensor_frames_;
  struct PublisherFigures {
    dds_idl::MapPublisherCounters counters;
    std::size_t pending = 0;
  };
  StageThread<PublisherFigures> publisher_stage_;  // last: joined before the publisher goes
};

}  // namespace semap::onboard
