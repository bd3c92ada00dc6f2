#pragma once

#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "semap/common/map_grid.hpp"
#include "semap/common/stamp.hpp"
#include "semap/dds_idl/map_client.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/fusion/fusion_config.hpp"
#include "semap/mapping/layered_map.hpp"

namespace semap::fusion {

struct RobotCounters {
  std::uint64_t blocks = 0;                   // blocks taken into the robot's layer
  std::uint64_t blocks_without_evidence = 0;  // skipped: nothing to merge
  std::uint64_t merges = 0;                   // times its layer was merged into the fused map
};

struct FusionCounters {
  std::uint64_t merge_rounds = 0;
  std::uint64_t blocks_fused = 0;  // fused blocks handed to the publisher
  double merge_seconds_total = 0.0;
  double merge_seconds_max = 0.0;
};

// Follows several robots' maps over DDS and publishes their fusion. Each robot's received
// blocks form that robot's evidence layer (source id = its position in the config + 1) in
// its own map frame. At the publication rate every changed layer is merged into the fused
// map as mapping::merge_into would, resampled by the robot's T_fused_robot, but only in the
// fused blocks the changed blocks reach (remerge_blocks), and those fused blocks are
// republished. mapping::LayeredMap keeps one layer per robot and a changed layer replaces
// that robot's previous evidence, so the fused Dirichlet evidence is
// alpha_0 + sum over robots of (alpha_r - alpha_0): every robot's evidence and the prior count
// exactly once however often a block is resent.
// The publisher reads the fused blocks from the fused map itself (the fusion is their
// BlockSource). Not thread safe: call from one thread.
class MapFusion : private dds_idl::BlockSource {
 public:
  MapFusion(const dds_idl::Participant& participant, MapFusionConfig config);

  // Takes what the robots sent; when a publication is due, merges the changed layers and
  // publishes. Returns the number of fused blocks handed to the publisher.
  std::size_t spin_once(common::Stamp now);

  std::size_t num_robots() const { return robots_.size(); }
  const dds_idl::MapClient& robot(std::size_t i) const { return *robots_.at(i).client; }
  const RobotCounters& robot_counters(std::size_t i) const { return robots_.at(i).counters; }
  const mapping::LayeredMap& fused_map() const { return fused_; }
  const dds_idl::MapPublisher& publisher() const { return publisher_; }
  const FusionCounters& counters() const { return counters_; }

 private:
  struct Robot {
    RobotSource source;
    mapping::SourceId id;
    std::unique_ptr<dds_idl::MapClient> client;
    mapping::EvidenceGrid layer;              // the robot's evidence in its own frame
    std::vector<common::BlockIndex> changed;  // since the last merge
    RobotCounters counters;
  };

  void take_blocks(Robot& robot);
  std::size_t merge_changed();
  // BlockSource: the fused map's blocks, as published.
  void for_each_block(const std::function<void(const common::BlockIndex&)>& f) const override;
  bool read(const common::BlockIndex& index, dds_idl::BlockSnapshot& out) const override;

  MapFusionConfig config_;
  mapping::MapParams params_;
  std::vector<Robot> robots_;
  mapping::LayeredMap fused_;
  dds_idl::MapPublisher publisher_;
  std::unordered_map<common::BlockIndex, std::uint32_t, common::BlockIndexHash> versions_;
  common::Stamp next_merge_;
  FusionCounters counters_;
};

}  // namespace semap::fusion
