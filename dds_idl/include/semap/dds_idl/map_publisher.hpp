#pragma once

#include <cstdint>
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
  double cloud_hz = 0.5;   // map_cloud for RViz; 0 disables it
};

struct MapPublisherCounters {
  std::uint64_t blocks_written = 0;
  std::uint64_t block_publications = 0;  // rounds with at least one changed block
  std::uint64_t clouds_written = 0;
  std::uint64_t infos_written = 0;
  // Rounds cut short because a reliable reader did not keep up within the blocking time; the
  // unsent blocks stay pending for the next round.
  std::uint64_t write_timeouts = 0;
};

// The mapping side of the map topics. The mapping stage hands over changed blocks with
// update(); spin_once() writes the blocks changed since the last round at blocks_hz (each
// block once, in its latest version), MapInfo when the map grew, and map_cloud at cloud_hz.
// Not thread safe: call from one thread.
class MapPublisher {
 public:
  MapPublisher(const Participant& participant, MapPublisherConfig config,
               MapDescription description);

  // Throws std::invalid_argument when the block's shape differs from the description.
  void update(BlockSnapshot&& block);
  // The same for a block the caller keeps: copied into the buffers of the version it replaces,
  // so a new version of a known block allocates nothing.
  void update(const BlockSnapshot& block);
  // Writes what is due at `now`; returns the number of blocks written.
  std::size_t spin_once(common::Stamp now);
  // Writes all pending blocks now, regardless of the rate. A write timeout ends the round
  // early (counted); other DDS failures throw DdsError.
  std::size_t publish_changed(common::Stamp now);
  void publish_cloud(common::Stamp now);

  std::size_t pending() const { return changed_.size(); }
  std::size_t num_blocks() const { return blocks_.size(); }
  const MapPublisherCounters& counters() const { return counters_; }
  // Readers currently matched on map_blocks.
  std::uint32_t matched_readers() const { return block_writer_.matched(); }

 private:
  void publish_info(common::Stamp now);
  void check_shape(const BlockSnapshot& block) const;
  // Marks `index` changed; `inserted`: the map grew.
  void mark_changed(const common::BlockIndex& index, bool inserted);

  MapPublisherConfig config_;
  MapDescription description_;
  Topic<msg::SemanticMapBlock> block_topic_;
  Writer<msg::SemanticMapBlock> block_writer_;
  Topic<msg::MapInfo> info_topic_;
  Writer<msg::MapInfo> info_writer_;
  Topic<msg::PointCloud2> cloud_topic_;
  Writer<msg::PointCloud2> cloud_writer_;
  MapCloud cloud_;
  std::unordered_map<common::BlockIndex, BlockSnapshot, common::BlockIndexHash> blocks_;
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> changed_;
  bool info_dirty_ = true;
  common::Stamp next_blocks_;
  common::Stamp next_cloud_;
  MapPublisherCounters counters_;
};

}  // namespace semap::dds_idl
