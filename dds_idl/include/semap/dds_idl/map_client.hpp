#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <unordered_set>
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
  // false: blocks are taken by poll() on the caller's thread. true: Cyclone's receive thread
  // takes and checks each block as it arrives (a listener), so no application thread has to
  // wake per sample and the client keeps up with a higher block rate (docs/dds.md).
  bool take_on_receive = false;
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
  common::CellState state = common::CellState::kUnknown;
  std::uint16_t cls = 0;
  float variance = 0.0f;
};

// Planner side: subscribes to one robot's map_blocks and map_info, validates every sample
// (bad ones are dropped and counted, never trusted), rebuilds the map and answers queries.
// Thanks to transient-local QoS a client that starts late still receives every block.
// Poll, query and read from one thread; with `take_on_receive` the receive thread also writes
// the map, under a lock that every member function takes (use with_blocks, not blocks()).
class MapClient {
 public:
  using BlockMap = std::unordered_map<common::BlockIndex, BlockSnapshot, common::BlockIndexHash>;

  MapClient(const Participant& participant, MapClientConfig config);
  // The receive thread holds `this`: stops it before the members go.
  ~MapClient();
  MapClient(const MapClient&) = delete;
  MapClient& operator=(const MapClient&) = delete;

  // Takes everything pending; returns the number of blocks accepted.
  std::size_t poll();
  // Polls until the map holds at least `count` blocks; false on timeout.
  bool wait_for_blocks(std::size_t count, std::chrono::milliseconds timeout);

  CellQuery query(const Eigen::Vector3f& p) const;
  // Map writers currently matched (0: the robot is not, or no longer, there).
  std::uint32_t matched_writers() const { return block_reader_.matched(); }

  // The received map; without take_on_receive only (the receive thread would change it under
  // the caller), where with_blocks works in both modes.
  const BlockMap& blocks() const;
  // Calls f(const BlockMap&) with the map locked against the receive thread; f must not call
  // back into this client.
  template <typename F>
  decltype(auto) with_blocks(F&& f) const {
    const std::lock_guard lock(mutex_);
    return f(blocks_);
  }
  std::size_t block_count() const;
  std::optional<MapDescription> info() const;
  MapClientCounters counters() const;
  std::string last_error() const;
  // Indices of blocks accepted since the last call, each once, in no particular order.
  std::vector<common::BlockIndex> take_changed();

  // Writes the occupied cells as an ASCII PCD (x y z class variance); throws on I/O errors.
  void save_pcd(const std::filesystem::path& path) const;

 private:
  static void on_data_available(dds_entity_t reader, void* self);
  // Takes the pending blocks; the caller holds mutex_.
  void take_blocks();
  void on_block(std::span<const std::uint8_t> cdr);
  void on_info(const msg::MapInfo& m);

  // Declared first: the listener may run as soon as the block reader exists.
  mutable std::mutex mutex_;
  // take_on_receive: signalled once wait_for_count_ blocks are held (wait_for_blocks).
  std::condition_variable accepted_cv_;
  std::size_t wait_for_count_ = SIZE_MAX;
  std::atomic<bool> constructed_{false};
  MapClientConfig config_;
  Topic<msg::SemanticMapBlock> block_topic_;
  Reader<msg::SemanticMapBlock> block_reader_;
  Topic<msg::MapInfo> info_topic_;
  Reader<msg::MapInfo> info_reader_;
  BlockMap blocks_;
  // A received block is read into this, checked, then swapped with its map entry, so that the
  // entry's old buffers take the next block: no allocation per block of a known shape.
  BlockSnapshot scratch_;
  // A set: a block changed many times between two take_changed() is listed once, and a client
  // that never asks holds at most one entry per block.
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> changed_;
  std::optional<MapDescription> info_;
  MapClientCounters counters_;
  std::string last_error_;
};

}  // namespace semap::dds_idl
