#pragma once

#include <Eigen/Core>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "semap/mapping/block_log.hpp"
#include "semap/mapping/semantic_map.hpp"

namespace semap::mapping {

struct CheckpointParams {
  std::filesystem::path path;  // the block log
  double interval_s = 10.0;    // 0: after every insert
  bool resume = false;         // load the log into the map at start
  bool durable = true;         // fsync each checkpoint (power-loss safe)
};

// Keeps a live SemanticMap recoverable: every interval the blocks changed since the last
// checkpoint are copied (on the mapping thread: a memcpy per block) and written to a BlockLog
// with a commit by the checkpoint's own thread, so a slow disk never stalls mapping. A crash
// (kill -9, power loss with durable) loses at most the evidence since the last commit; with
// resume the next start loads the log and continues from there.
//
// While the writer is busy, changes accumulate and go in its next checkpoint, so a slow disk
// makes checkpoints rarer rather than queueing copies of the map.
//
// A checkpoint that cannot be written (disk full, file size limit, I/O error) is counted, with
// its error, and never thrown: the log keeps its last complete checkpoint (BlockLog cuts off
// the failed write), the blocks of the failed checkpoint go back among the changed ones, and
// the next interval tries again with everything changed since the last commit, so writing
// resumes by itself once there is room. Mapping goes on meanwhile.
class MapCheckpoint {
 public:
  struct Stats {
    std::uint64_t checkpoints = 0;     // commits written
    std::uint64_t blocks_written = 0;  // block records
    double last_write_s = 0;           // writer time of the last checkpoint
    double max_write_s = 0;
    std::uint64_t log_bytes = 0;
    std::uint64_t resumed_blocks = 0;   // loaded at start
    std::uint64_t resumed_scans = 0;    // scans the resumed map had seen
    std::uint64_t committed_scans = 0;  // the scans of the last commit in the log
    std::uint64_t write_failures = 0;   // checkpoints (or compactions) not written
    bool failing = false;               // the last checkpoint failed: the log is behind
    std::string last_error;             // of the last failure: file, step, errno text
  };

  // Opens the log (BlockLogError when it belongs to other map parameters, or, without resume,
  // when it already holds a map). With resume and `load` true, restores every block into
  // `map`; a pager that loads blocks as the robot gets near them passes false.
  MapCheckpoint(SemanticMap& map, const CheckpointParams& params, bool load = true);
  ~MapCheckpoint();
  MapCheckpoint(const MapCheckpoint&) = delete;
  MapCheckpoint& operator=(const MapCheckpoint&) = delete;

  // Mapping thread, after each insert: notes the blocks it wrote and starts a checkpoint when
  // the interval has passed and the writer is free.
  void after_insert(const InsertResult& result);
  // Mapping thread, also while no scans arrive: starts the checkpoint of changes that waited
  // for a busy writer, once the interval has passed.
  void poll();
  // Mapping thread: writes all changes and returns once they are committed (a clean exit).
  void flush();

  BlockLog& log() { return log_; }
  // The map's frame as recorded in the log (a resumed map's), and recording it.
  std::optional<MapFrame> frame() const { return log_.frame(); }
  void set_frame(const MapFrame& frame) { log_.set_frame(frame); }
  Stats stats() const;
  // A damaged log tail cut on opening ("" when none).
  const std::string& damage() const { return log_.damage(); }

 private:
  struct BlockCopy {
    common::BlockIndex index;
    std::vector<float> evidence;
    std::vector<std::uint64_t> observed;
  };
  struct Batch {
    std::vector<BlockCopy> blocks;
    std::uint64_t scans = 0;
  };

  Batch copy_dirty();
  // Never throws: a failure is counted and its blocks are left in retry_.
  void write(const Batch& batch);
  void failed(const Batch& batch, const std::string& error);
  // Under mutex_: the blocks of a failed checkpoint join the changed ones (mapping thread).
  void take_retries();
  void run(std::stop_token stop);

  SemanticMap& map_;
  CheckpointParams params_;
  BlockLog log_;
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> dirty_;
  std::chrono::steady_clock::time_point last_;

  mutable std::mutex mutex_;
  std::condition_variable_any wake_;
  std::condition_variable done_;
  bool pending_ = false;  // batch_ waits for or is being written by the writer
  Batch batch_;
  // Blocks of a failed checkpoint, to be copied again for the next one.
  std::unordered_set<common::BlockIndex, common::BlockIndexHash> retry_;
  // No compaction until the log is past this size again: a compaction that failed for want
  // of room would fail the same way on every checkpoint until the disk has room again.
  std::uint64_t compact_after_bytes_ = 0;
  Stats stats_;
  std::jthread writer_;
};

// Bounds a live map's memory to a radius around the robot: before each insert, blocks whose
// centre is farther than radius + one block from the robot are written to the log and dropped
// from memory; blocks of the log within the radius come back. The extra block of hysteresis
// keeps a block on the boundary from bouncing. With radius >= max_range + ell + one block
// diagonal every block a scan touches is in memory, so no evidence is split between the two.
class MapPager {
 public:
  struct Stats {
    std::uint64_t evicted = 0;
    std::uint64_t restored = 0;
    std::uint64_t late_restores = 0;  // blocks an insert reached before update() restored them
    // Evictions whose block could not be written to the log (disk full): the block stays in
    // memory, so memory grows past the radius rather than the map losing evidence.
    std::uint64_t write_failures = 0;
    bool failing = false;  // the last eviction attempt failed
    std::string last_error;
  };

  // `log`'s blocks not in `map` count as paged out (a resumed map). Throws
  // std::invalid_argument unless radius_m > 0.
  MapPager(SemanticMap& map, BlockLog& log, double radius_m);

  // Pages out the blocks beyond the radius and back in those within it; returns the blocks it
  // paged out.
  std::vector<common::BlockIndex> update(const Eigen::Vector3f& robot);
  // After each insert (before MapCheckpoint::after_insert): a paged-out block the insert
  // reached (radius too small for the sensor) was started again from zero; its evidence from
  // the log is added back, so nothing is lost.
  void after_insert(const InsertResult& result);
  // Blocks in the log and not in memory.
  std::size_t paged_out() const { return paged_out_; }
  const Stats& stats() const { return stats_; }

 private:
  SemanticMap& map_;
  BlockLog& log_;
  double radius_;
  void mark_out(const common::BlockIndex& index);
  // Removes `index` from the paged-out blocks; false when it is not among them.
  bool take_out(const common::BlockIndex& index);
  common::BlockIndex region_of(const common::BlockIndex& index) const;

  // Paged-out blocks by region (cubes of region_side_ blocks, about the radius), so that an
  // update looks at the 27 regions around the robot, not at every block a long drive left.
  std::unordered_map<common::BlockIndex, std::vector<common::BlockIndex>, common::BlockIndexHash>
      out_;
  std::size_t paged_out_ = 0;
  std::int32_t region_side_;
  Stats stats_;
};

}  // namespace semap::mapping
