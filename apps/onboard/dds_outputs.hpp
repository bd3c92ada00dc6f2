#pragma once

#include <memory>
#include <mutex>
#include <vector>

#include "estimation_stage.hpp"
#include "mapping_stage.hpp"
#include "onboard_config.hpp"
#include "semap/dds_idl/health.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/dds_idl/participant.hpp"
#include "semap/dds_idl/topic.hpp"
#include "semap/dds_idl/types.hpp"
#include "semap/dds_idl/writer.hpp"

namespace semap::onboard {

// The robot's DDS side: odometry from the estimation stage, map blocks, MapInfo and map_cloud
// from the mapping stage. Each stage calls only its own method, from its own thread.
class DdsOutputs {
 public:
  explicit DdsOutputs(const OnboardConfig& config);

  void publish_pose(const PoseOutput& pose);
  void publish_blocks(std::vector<dds_idl::BlockSnapshot>&& blocks, common::Stamp now);
  // From the main thread, at 1 Hz.
  void publish_health(const dds_idl::HealthReport& report);

  std::uint64_t odometry_written() const { return odometry_written_.load(); }
  std::uint64_t health_written() const { return health_written_; }
  dds_idl::MapPublisherCounters map_counters() const;
  // Changed blocks waiting for the next publication round.
  std::size_t map_pending() const;

 private:
  const OnboardConfig& config_;
  dds_idl::Participant participant_;
  dds_idl::Topic<dds_idl::msg::Odometry> odometry_topic_;
  dds_idl::Writer<dds_idl::msg::Odometry> odometry_writer_;
  std::atomic<std::uint64_t> odometry_written_{0};
  dds_idl::Topic<dds_idl::msg::Health> health_topic_;
  dds_idl::Writer<dds_idl::msg::Health> health_writer_;
  dds_idl::MapPublisher map_publisher_;
  mutable std::mutex map_counters_mutex_;
  dds_idl::MapPublisherCounters map_counters_;
  std::size_t map_pending_ = 0;
  std::uint64_t health_written_ = 0;  // main thread only
};

}  // namespace semap::onboard
