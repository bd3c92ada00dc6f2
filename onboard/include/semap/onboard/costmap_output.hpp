#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <unordered_set>

#include "semap/common/map_grid.hpp"
#include "semap/common/stamp.hpp"
#include "semap/dds_idl/participant.hpp"
#include "semap/dds_idl/topic.hpp"
#include "semap/dds_idl/types.hpp"
#include "semap/dds_idl/writer.hpp"
#include "semap/mapping/costmap.hpp"

namespace semap::onboard {

// The `costmap:` section (mapping::costmap_params_from_config plus the rate).
struct CostmapConfig {
  mapping::CostmapParams params;
  double publish_hz = 1.0;
};

// Where the costmap output reads the map: the mapping stage, under its map lock.
class CostmapSource {
 public:
  virtual ~CostmapSource() = default;
  virtual mapping::Costmap build_costmap(const mapping::CostmapParams& p,
                                         const Eigen::Vector2d& centre) const = 0;
  virtual mapping::CostmapUpdate update_costmap(
      mapping::Costmap& costmap, const mapping::CostmapParams& p,
      std::span<const common::BlockIndex> changed) const = 0;
};

// nav_msgs/OccupancyGrid of `costmap` in `frame_id` (the map frame, origin z 0, no rotation),
// borrowing its data: valid while `costmap` is unchanged.
void to_msg(const mapping::Costmap& costmap, common::Stamp stamp, const std::string& frame_id,
            dds_idl::msg::OccupancyGrid& out);
// map_msgs/OccupancyGridUpdate of a rectangle of the costmap, borrowing its data.
void to_msg(const mapping::CostmapUpdate& update, common::Stamp stamp, const std::string& frame_id,
            dds_idl::msg::OccupancyGridUpdate& out);

// The semantic costmap for nav2 on `rt/<ns>/semap/costmap` (reliable, transient local, keep
// last 1: nav2's static layer, or any late joiner, gets the current grid) and
// `costmap_updates` (the rectangle that changed, reliable, volatile, keep last 10). The window
// follows the robot: it is rebuilt around it when the robot leaves its middle half, and
// otherwise updated from the map blocks that changed since the last round.
class CostmapOutput {
 public:
  struct Counters {
    std::uint64_t grids_written = 0;
    std::uint64_t updates_written = 0;
    std::uint64_t rebuilds = 0;
    double last_seconds = 0;  // building or updating the last round's grid
  };

  CostmapOutput(const dds_idl::Participant& participant, const std::string& ns,
                std::string frame_id, const CostmapConfig& config, const CostmapSource& source);

  // Publisher thread: a block the map changed.
  void changed(const common::BlockIndex& block);
  // Publisher thread: a round when one is due and the robot's position is known.
  void spin_once(common::Stamp now, const std::optional<Eigen::Vector2d>& robot);
  const Counters& counters() const { return counters_; }
  // Hands the costmap and its updates to `tap` too; before the publisher's thread starts.
  void attach_tap(dds_idl::MessageTap& tap) {
    grid_writer_.attach_tap(tap);
    update_writer_.attach_tap(tap);
  }

 private:
  bool needs_rebuild(const Eigen::Vector2d& robot) const;

  std::string frame_id_;
  CostmapConfig config_;
  const CostmapSource& source_;
  dds_idl::Topic<dds_idl::msg::OccupancyGrid> grid_topic_;
  dds_idl::Writer<dds_idl::msg::OccupancyGrid> grid_writer_;
  dds_idl::Topic<dds_idl::msg::OccupancyGridUpdate> update_topic_;
  dds_idl::Writer<dds_idl::msg::OccupancyGridUpdate> update_writer_;
  std::optional<mapping::Costmap> costmap_;
  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> pending_;
  common::Stamp next_;
  Counters counters_;
};

}  // namespace semap::onboard
