#pragma once

#include <array>
#include <chrono>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "semap/dds_idl/block_codec.hpp"
#include "semap/dds_idl/block_snapshot.hpp"
#include "semap/dds_idl/map_description.hpp"
#include "semap/dds_idl/reader.hpp"

namespace semap::dds_idl {

struct MapClientConfig {
  std::string ns;  // topic namespace of the robot to follow
  // Expected shape; zero fields are taken from MapInfo, or else from the first valid block.
  BlockLimits limits;
};

struct MapClientCounters {
  std::uint64_t accepted = 0;
  std::uint64_t stale = 0;                  // older version than the block already held
  std::array<std::uint64_t, 7> rejected{};  // indexed by BlockReject
  std::uint64_t infos = 0;
  std::uint64_t infos_rejected = 0;

  std::uint64_t rejected_total() const;
  std::uint64_t rejected_for(BlockReject r) const { return rejected[static_cast<std::size_t>(r)]; }
};

// What the map says about one point.
struct CellQuery {
  bool known_block = false;  // false: no block received for this place
  CellState state = CellState::kUnknown;
  std::uint16_t cls = 0;
  float variance = 0.0f;
};

// Planner side: subscribes to one robot's map_blocks and map_info, validates every sample
// (bad ones are dropped and counted, never trusted), rebuilds the map and answers queries.
// Thanks to transient-local QoS a client that starts late still receives every block.
// Not thread safe: poll and query from one thread.
class MapClient {
 public:
  MapClient(const Participant& participant, MapClientConfig config);

  // Takes everything pending; returns the number of blocks accepted.
  std::size_t poll();
  // Polls until the map holds at least `count` blocks; false on timeout.
  bool wait_for_blocks(std::size_t count, std::chrono::milliseconds timeout);

  CellQuery query(const Eigen::Vector3f& p) const;

  const std::unordered_map<BlockIndex, BlockSnapshot, BlockIndexHash>& blocks() const {
    return blocks_;
  }
  const std::optional<MapDescription>& info() const { return info_; }
  const MapClientCounters& counters() const { return counters_; }
  const std::string& last_error() const { return last_error_; }
  // Indices of blocks accepted since the last call.
  std::vector<BlockIndex> take_changed();

  // Writes the occupied cells as an ASCII PCD (x y z class variance); throws on I/O errors.
  void save_pcd(const std::filesystem::path& path) const;

 private:
  void on_block(std::span<const std::uint8_t> cdr);
  void on_info(const msg::MapInfo& m);

  MapClientConfig config_;
  Topic<msg::SemanticMapBlock> block_topic_;
  Reader<msg::SemanticMapBlock> block_reader_;
  Topic<msg::MapInfo> info_topic_;
  Reader<msg::MapInfo> info_reader_;
  std::unordered_map<BlockIndex, BlockSnapshot, BlockIndexHash> blocks_;
  // A received block is read into this, checked, then swapped with its map entry, so that the
  // entry's old buffers take the next block: no allocation per block of a known shape.
  BlockSnapshot scratch_;
  std::vector<BlockIndex> changed_;
  std::optional<MapDescription> info_;
  MapClientCounters counters_;
  std::string last_error_;
};

}  // namespace semap::dds_idl
