#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <vector>

#include "latency_window.hpp"
#include "onboard_config.hpp"
#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/dds_idl/block_snapshot.hpp"
#include "semap/dds_idl/map_description.hpp"
#include "semap/mapping/map_checkpoint.hpp"
#include "semap/mapping/semantic_map.hpp"

namespace semap::onboard {

struct MappingStageStats {
  std::uint64_t scans = 0;  // this run's
  std::uint64_t points = 0;
  std::uint64_t blocks_changed = 0;  // block snapshots handed to the publisher
  double insert_seconds_total = 0.0;
  double insert_seconds_max = 0.0;
  mapping::MapStats map;
  mapping::MapCheckpoint::Stats checkpoint;  // zeros without a checkpoint
  mapping::MapPager::Stats pager;            // zeros without a memory radius
};

// Owns the SemanticMap on its own thread: inserts every posed cloud and hands a snapshot of
// each block the insert wrote to the block sink (the DDS map publisher). With a checkpoint
// path it keeps the map recoverable (MapCheckpoint) and, with a memory radius, bounded
// (MapPager).
class MappingStage {
 public:
  using BlockSink = std::function<void(std::vector<dds_idl::BlockSnapshot>&&, common::Stamp)>;

  // Throws mapping::BlockLogError when the checkpoint log cannot be opened or belongs to a map
  // with other parameters (it is never overwritten).
  MappingStage(const OnboardConfig& config, common::SpscRing<common::LabeledCloud>& clouds,
               BlockSink sink, const std::filesystem::path& checkpoint_path);
  ~MappingStage();
  MappingStage(const MappingStage&) = delete;
  MappingStage& operator=(const MappingStage&) = delete;

  void start();
  void stop();
  MappingStageStats stats() const;
  // Age of each cloud (its image's capture stamp) once it is in the map.
  const LatencyWindow& latency() const { return latency_; }
  // Only after stop(): the map belongs to the stage thread while it runs. With a memory
  // radius, the whole map read back from the checkpoint log, else the map itself.
  const mapping::SemanticMap& map();
  // The frame of the checkpoint's map, when it has one (a resumed map is only right in it).
  std::optional<mapping::MapFrame> map_frame() const {
    return checkpoint_ ? checkpoint_->frame() : std::nullopt;
  }
  // Records the map's frame in the checkpoint once the estimator has anchored it.
  void record_map_frame(const mapping::MapFrame& frame);
  // What opening the checkpoint found ("" when nothing to report): a cut damaged tail.
  std::string checkpoint_damage() const { return checkpoint_ ? checkpoint_->damage() : ""; }

 private:
  void run(std::stop_token stop);
  void insert(const common::LabeledCloud& cloud);
  std::vector<dds_idl::BlockSnapshot> snapshots_of(const std::vector<common::BlockIndex>& updated);

  const OnboardConfig& config_;
  common::SpscRing<common::LabeledCloud>& clouds_;
  BlockSink sink_;
  mapping::SemanticMap map_;
  std::unique_ptr<mapping::MapCheckpoint> checkpoint_;
  std::unique_ptr<mapping::MapPager> pager_;
  std::unique_ptr<mapping::SemanticMap> full_map_;  // map() with a pager
  std::unordered_map<common::BlockIndex, std::uint32_t, common::BlockIndexHash> versions_;
  MappingStageStats local_;
  mutable std::mutex stats_mutex_;
  MappingStageStats shared_;
  LatencyWindow latency_;
  std::jthread thread_;
};

// The map's shape and its palette's class names and colours (0xRRGGBB), for MapInfo.
dds_idl::MapDescription describe_map(const OnboardConfig& config);

// A block of the map in the form the DDS layer publishes.
dds_idl::BlockSnapshot to_snapshot(const mapping::SemanticMap& map, const common::BlockIndex& index,
                                   const mapping::Block& block, std::uint32_t version);

}  // namespace semap::onboard
