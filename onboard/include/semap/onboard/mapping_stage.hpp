#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <thread>
#include <unordered_map>
#include <vector>

#include "semap/common/latency_window.hpp"
#include "semap/common/messages.hpp"
#include "semap/common/spsc_ring.hpp"
#include "semap/dds_idl/block_snapshot.hpp"
#include "semap/dds_idl/health.hpp"
#include "semap/dds_idl/map_description.hpp"
#include "semap/dds_idl/map_publisher.hpp"
#include "semap/mapping/map_checkpoint.hpp"
#include "semap/mapping/semantic_map.hpp"
#include "semap/onboard/costmap_output.hpp"
#include "semap/onboard/onboard_config.hpp"
#include "semap/onboard/stage_thread.hpp"
#include "semap/onboard/write_failure_log.hpp"

namespace semap::onboard {

struct MappingStageStats {
  std::uint64_t scans = 0;  // this run's
  std::uint64_t points = 0;
  std::uint64_t blocks_changed = 0;  // block changes told to the publisher
  double insert_seconds_total = 0.0;
  double insert_seconds_max = 0.0;
  mapping::MapStats map;
  mapping::MapCheckpoint::Stats checkpoint;  // zeros without a checkpoint
  mapping::MapPager::Stats pager;            // zeros without a memory radius
};

// The checkpoint log's writes as the health report gives them: checkpoints written, failed
// checkpoints and evictions (disk full), whether the last attempt failed and its error.
dds_idl::WriterHealthData checkpoint_health(const MappingStageStats& stats,
                                            const std::filesystem::path& path);

// Owns the SemanticMap on its own thread: inserts every posed cloud and tells the block sink
// (the DDS map publisher) which blocks the insert wrote and which the pager moved to the log. The
// publisher reads them, on its own thread and at its own rate, through blocks(): a read-only view
// of the map that shares a lock with the inserts, so the map is held once. With a checkpoint path
// the stage keeps the map recoverable (MapCheckpoint) and, with a memory radius, bounded
// (MapPager). A checkpoint that cannot be written (disk full) never stops mapping: it is counted,
// logged and retried.
class MappingStage : private dds_idl::BlockSource, private CostmapSource {
 public:
  // Called on the mapping thread with the blocks an insert wrote and those paged out before
  // it; must not block.
  using BlockSink = std::function<void(const std::vector<common::BlockIndex>& updated,
                                       const std::vector<common::BlockIndex>& paged_out)>;

  // Throws mapping::BlockLogError when the checkpoint log cannot be opened or belongs to a map
  // with other parameters (it is never overwritten).
  MappingStage(const MappingConfig& config, common::SpscRing<common::LabeledCloud>& clouds,
               BlockSink sink, const std::filesystem::path& checkpoint_path);
  ~MappingStage();
  MappingStage(const MappingStage&) = delete;
  MappingStage& operator=(const MappingStage&) = delete;

  // `cpus`: the CPUs its thread may run on (realtime.stage_cpus; empty: any).
  void start(std::vector<int> cpus = {});
  void stop();
  MappingStageStats stats() const;
  // Age of each cloud (its image's capture stamp) once its cells are in the map (readable by
  // the publisher); clouds held from before the heading was known (older than one already
  // mapped) are left out.
  const common::LatencyWindow& latency() const { return latency_; }
  // Time each insert took, from taking the cloud (its wait for the map's lock included) until
  // its cells are in the map.
  const common::LatencyWindow& insert_time() const { return insert_time_; }
  // Where the age comes from before the insert: each live cloud's age (its image's capture
  // stamp) when the stage takes it from its ring, and how long the insert then waited for the
  // map's lock (the publisher's readers).
  const common::LatencyWindow& taken_age() const { return taken_age_; }
  const common::LatencyWindow& lock_wait() const { return lock_wait_; }
  // The map's blocks as the publisher sends them; safe from any thread. A paged-out block is
  // read from the checkpoint log; for_each_block lists the blocks in memory.
  const dds_idl::BlockSource& blocks() const { return *this; }
  // The costmap of the map's blocks in memory, for the publisher's thread; safe from any thread.
  const CostmapSource& costmaps() const { return *this; }
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
  // Mapping thread: the checkpoint's and pager's figures into the stage's, their failures
  // into the log (rate-limited).
  void note_writes();
  // BlockSource, for the publisher's thread.
  void for_each_block(const std::function<void(const common::BlockIndex&)>& f) const override;
  bool read(const common::BlockIndex& index, dds_idl::BlockSnapshot& out) const override;
  bool read_cells(const common::BlockIndex& index, dds_idl::BlockSnapshot& out) const override;
  bool read_block(const common::BlockIndex& index, bool with_evidence,
                  dds_idl::BlockSnapshot& out) const;
  // CostmapSource, for the publisher's thread.
  mapping::Costmap build_costmap(const mapping::CostmapParams& p,
                                 const Eigen::Vector2d& centre) const override;
  mapping::CostmapUpdate update_costmap(mapping::Costmap& costmap, const mapping::CostmapParams& p,
                                        std::span<const common::BlockIndex> changed) const override;

  const MappingConfig& config_;
  common::SpscRing<common::LabeledCloud>& clouds_;
  BlockSink sink_;
  // The mapping thread writes the map (and versions_) under an exclusive lock; readers share.
  mutable std::shared_mutex map_mutex_;
  mapping::SemanticMap map_;
  std::unique_ptr<mapping::MapCheckpoint> checkpoint_;
  std::unique_ptr<mapping::MapPager> pager_;
  std::unique_ptr<mapping::SemanticMap> full_map_;  // map() with a pager
  std::unordered_map<common::BlockIndex, std::uint32_t, common::BlockIndexHash> versions_;
  common::LatencyWindow latency_;
  common::Stamp newest_mapped_;  // clouds older than this were held back: not in latency_
  common::LatencyWindow taken_age_;
  common::LatencyWindow lock_wait_;
  common::LatencyWindow insert_time_;
  std::chrono::steady_clock::time_point stats_taken_;  // figures().map last counted
  std::unique_ptr<WriteFailureLog> write_log_;         // with a checkpoint
  StageThread<MappingStageStats> stage_;               // last: joined before the members it uses
};

// The map's shape and its palette's class names and colours (0xRRGGBB), for MapInfo.
dds_idl::MapDescription describe_map(const MappingConfig& config);

// A block of the map in the form the DDS layer publishes, into `out` (its buffers reused); its
// evidence only `with_evidence`.
void to_snapshot(const mapping::SemanticMap& map, const common::BlockIndex& index,
                 const mapping::Block& block, std::uint32_t version, bool with_evidence,
                 dds_idl::BlockSnapshot& out);

}  // namespace semap::onboard
