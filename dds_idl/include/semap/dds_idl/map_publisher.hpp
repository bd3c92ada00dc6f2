#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include "semap/common/stamp.hpp"
#include "semap/dds_idl/block_snapshot.hpp"
#include "semap/dds_idl/map_cloud.hpp"
#include "semap/dds_idl/map_description.hpp"
#include "semap/dds_idl/writer.hpp"

namespace semap::dds_idl {

struct MapPublisherConfig {
  std::string ns;  // topic namespace: "" or e.g. "robot1"
  std::string frame_id = "map";
  double blocks_hz = 2.0;  // changed blocks and MapInfo
  double cloud_hz = 0.5;   // map_cloud for RViz; 0 disables it and map_cloud_updates
};

struct MapPublisherCounters {
  std::uint64_t blocks_written = 0;
  std::uint64_t block_publications = 0;  // rounds with at least one changed block
  std::uint64_t clouds_written = 0;
  std::uint64_t cloud_updates_written = 0;
  std::uint64_t cloud_update_points = 0;
  std::uint64_t infos_written = 0;
  // Rounds cut short because a reliable reader did not keep up within the blocking time; the
  // unsent blocks stay pending for the next round.
  std::uint64_t write_timeouts = 0;
  std::uint64_t blocks_forgotten = 0;  // taken out of the writer's history (forget())
};

// Where the publisher reads the blocks it sends: the map's own storage, read-only, so the
// publisher holds no copy of the map. Called from the publisher's thread; a source over a map
// that another thread writes locks against that writer.
class BlockSource {
 public:
  virtual ~BlockSource() = default;
  // Calls f(index) for every block there is now.
  virtual void for_each_block(const std::function<void(const common::BlockIndex&)>& f) const = 0;
  // The block at `index` into `out`, reusing its buffers; false when there is none (any more).
  virtual bool read(const common::BlockIndex& index, BlockSnapshot& out) const = 0;
  // The same without evidence (out.evidence empty), for the map cloud; a source that can skip
  // copying the evidence overrides it.
  virtual bool read_cells(const common::BlockIndex& index, BlockSnapshot& out) const {
    if (!read(index, out)) return false;
    out.evidence.clear();
    return true;
  }
};

// A BlockSource that keeps snapshots: for producers that hold no semap map (simulated blocks,
// tests). Not thread safe.
class SnapshotStore : public BlockSource {
 public:
  // Keeps `block`, replacing the version at its index; returns the index.
  common::BlockIndex put(BlockSnapshot block);
  std::size_t size() const { return blocks_.size(); }

  void for_each_block(const std::function<void(const common::BlockIndex&)>& f) const override;
  bool read(const common::BlockIndex& index, BlockSnapshot& out) const override;

 private:
  std::unordered_map<common::BlockIndex, BlockSnapshot, common::BlockIndexHash> blocks_;
};

// The mapping side of the map topics. The producer says which blocks changed with changed();
// spin_once() reads those from the source and writes them at blocks_hz (each block once, in
// its latest version) after, in the same round, map_cloud_updates (the cells of those blocks
// whose occupancy or class changed since they were last sent), MapInfo when the map grew, and
// map_cloud (every block's occupied cells) at cloud_hz. Not thread safe: call from one thread.
class MapPublisher {
 public:
  // `source` outlives the publisher.
  MapPublisher(const Participant& participant, MapPublisherConfig config,
               MapDescription description, const BlockSource& source);

  // Marks a block changed: it goes out in the next round, read from the source then.
  void changed(const common::BlockIndex& index);
  // After the next round, takes the block out of the writer's history (a paged-out block): the
  // subscribers keep it, late joiners do not get it, and the robot's memory does not hold it.
  // A later change publishes it again.
  void forget(const common::BlockIndex& index);
  // Writes what is due at `now`; returns the number of blocks written.
  std::size_t spin_once(common::Stamp now);
  // When a round is due at `now`, writes its map_cloud_updates already, so that what the caller
  // writes next (the costmap) goes out before the round's blocks; spin_once then skips them.
  void spin_updates(common::Stamp now);
  // Writes all pending blocks now, regardless of the rate. A write timeout ends the round
  // early (counted); other DDS failures throw DdsError. Throws std::invalid_argument when the
  // source gives a block whose shape differs from the description.
  std::size_t publish_changed(common::Stamp now);
  void publish_cloud(common::Stamp now);
  // Hands map_info, map_cloud and map_cloud_updates to `tap` as they are written (the blocks
  // stay DDS-only). Before the publisher's thread starts.
  void attach_tap(MessageTap& tap) {
    info_writer_.attach_tap(tap);
    cloud_writer_.attach_tap(tap);
    updates_writer_.attach_tap(tap);
  }

  std::size_t pending() const { return changed_.size(); }
  // Blocks published so far (a block the source later drops, such as a paged-out one, stays
  // with subscribers and counts).
  std::size_t num_blocks() const { return known_.size(); }
  const MapPublisherCounters& counters() const { return counters_; }
  // Readers currently matched on map_blocks.
  std::uint32_t matched_readers() const { return block_writer_.matched(); }

 private:
  void publish_info(common::Stamp now);
  void publish_cloud_updates(common::Stamp now);
  void check_shape(const BlockSnapshot& block) const;

  MapPublisherConfig config_;
  MapDescription description_;
  Topic<msg::SemanticMapBlock> block_topic_;
  Writer<msg::SemanticMapBlock> block_writer_;
  Topic<msg::MapInfo> info_topic_;
  Writer<msg::MapInfo> info_writer_;
  Topic<msg::PointCloud2> cloud_topic_;
  Writer<msg::PointCloud2> cloud_writer_;
  MapCloud cloud_;
  Topic<msg::PointCloud2> updates_topic_;
  Writer<msg::PointCloud2> updates_writer_;
  MapCloud updates_;
  // Per published block, each cell's class as map_cloud_updates last gave it
  // (MapCloud::kRemovedClass: not occupied).
  std::unordered_map<common::BlockIndex, std::vector<std::uint16_t>, common::BlockIndexHash>
      sent_classes_;
  const BlockSource& source_;
  BlockSnapshot scratch_;  // the block being written, its buffers reused
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> known_;
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> changed_;
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> forgotten_;
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> in_history_;  // written, kept
  bool info_dirty_ = true;
  bool updates_due_ = false;  // blocks changed since the last map_cloud_updates
  common::Stamp next_blocks_;
  common::Stamp next_cloud_;
  MapPublisherCounters counters_;
};

}  // namespace semap::dds_idl
