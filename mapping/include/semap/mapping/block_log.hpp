#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

#include "semap/common/map_grid.hpp"
#include "semap/mapping/map_params.hpp"

namespace semap::mapping {

class SemanticMap;

// Thrown for a log that cannot be used at all (wrong file, other map parameters, I/O
// failure); the message names the file and the field or step.
class BlockLogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Where the map's frame lies on the Earth: the geodetic origin (latitude and longitude in
// degrees, altitude above the ellipsoid in m) of its local ENU frame. A resumed map is only
// right in the same frame.
using MapFrame = std::array<double, 3>;

// Where each block's latest record lies in a log's bytes.
struct BlockLogEntry {
  std::uint64_t offset = 0;  // of the record
  std::uint64_t bytes = 0;   // whole record
  std::uint64_t scan = 0;    // the map's scan count when the block was copied
};

// What a log's bytes hold up to their last commit.
struct BlockLogScan {
  std::unordered_map<common::BlockIndex, BlockLogEntry, common::BlockIndexHash> blocks;
  std::uint64_t committed_scans = 0;
  std::uint64_t commits = 0;
  std::optional<MapFrame> frame;
  std::uint64_t end = 0;  // bytes up to and with the last commit (the header when none)
  // Why reading stopped before the end of the bytes ("" when it did not): a torn or damaged
  // record, with its byte offset.
  std::string damage;
};

// Reads a log's bytes (header and records) for a map with `params`. Throws BlockLogError when
// the header is not a block log's or was written for other parameters (naming the field);
// a damaged record ends the scan, reported in `damage`.
BlockLogScan scan_block_log(std::span<const std::uint8_t> bytes, const MapParams& params,
                            const std::string& name);

// An append-only file of map blocks: the robot's crash-safe checkpoint and the pager's store.
// Each record holds one block (evidence and observed bits) or a commit, with its own CRC-32:
//   header  "SEMAPLOG", version, method, cells per side, K, resolution, prior, sf2, ell, CRC
//   block   type 1, length, x y z, scan, K * cells floats, observed words, CRC
//   commit  type 2, length, scans, CRC
//   frame   type 3, length, latitude, longitude, altitude (MapFrame), CRC
// (little-endian, as the robot's CPU writes them). A commit says that the records before it
// are the map after `scans` scans. A crash can only leave a torn tail after the last commit;
// opening the log cuts it off, so the log resumes from the last complete checkpoint.
//
// A write that fails (disk full, file size limit, I/O error) throws BlockLogError naming the
// file, the step and the errno text, and first cuts off what it wrote: the log keeps ending
// with a whole record, the last commit stays the last checkpoint, and the log can be appended
// to again once there is room.
//
// Thread-safe: the checkpoint thread appends and commits while the mapping thread's pager
// appends and loads blocks.
class BlockLog {
 public:
  // Opens `path`, creating it when missing. Throws BlockLogError as scan_block_log does, or
  // naming the failing I/O step. `durable`: commits fsync the file (power-loss safe). A new
  // log whose header does not fit (a full disk) opens all the same: the header is written
  // with the first record that fits.
  BlockLog(std::filesystem::path path, const MapParams& params, bool durable = true);
  ~BlockLog();
  BlockLog(const BlockLog&) = delete;
  BlockLog& operator=(const BlockLog&) = delete;

  // Appends a block copied when the map had `scan` scans. Ignored when the log already holds a
  // newer copy of it (a pager wrote the block out after the checkpoint copied it).
  void append(const common::BlockIndex& index, std::uint64_t scan, std::span<const float> evidence,
              std::span<const std::uint64_t> observed);
  // Appends a commit for the map after `scans` scans (fsyncs when durable). When the write or
  // the fsync fails the commit is taken back: committed_scans() stays the last one.
  void commit(std::uint64_t scans);
  // Records the map's frame; it is written with the next commit (so this never fails).
  void set_frame(const MapFrame& frame);
  std::optional<MapFrame> frame() const;
  // Restores the latest copy of a block into `map` (SemanticMap::restore_block); false when the
  // log has none. Throws BlockLogError when the record cannot be read back.
  bool load(const common::BlockIndex& index, SemanticMap& map) const;
  // The latest copy of a block (K * cells floats and its observed words); false when the log
  // has none. Throws BlockLogError as load does.
  bool read(const common::BlockIndex& index, std::vector<float>& evidence,
            std::vector<std::uint64_t>& observed) const;
  // Restores every block; returns how many.
  std::size_t load_all(SemanticMap& map) const;
  // Rewrites the file with only the latest record of each block (temp + fsync + rename) when
  // it holds more than `factor` times their bytes. Returns true when it did.
  bool compact(double factor = 3.0);

  bool contains(const common::BlockIndex& index) const;
  std::vector<common::BlockIndex> blocks() const;
  std::uint64_t committed_scans() const;
  std::uint64_t bytes() const;
  const std::filesystem::path& path() const { return path_; }
  // What opening found: a damaged tail that was cut ("" when none).
  const std::string& damage() const { return damage_; }

 private:
  // Writes all of `bytes` at the end (with the header first when it is pending) or throws,
  // having cut the file back to where it ended.
  void write_at_end(std::span<const std::uint8_t> bytes);
  void cut_back_to(std::uint64_t end);
  std::vector<std::uint8_t> read_record(const BlockLogEntry& entry) const;

  std::filesystem::path path_;
  MapParams params_;
  bool durable_;
  int fd_ = -1;
  mutable std::mutex mutex_;
  std::unordered_map<common::BlockIndex, BlockLogEntry, common::BlockIndexHash> blocks_;
  std::uint64_t end_ = 0;
  std::uint64_t committed_scans_ = 0;
  std::optional<MapFrame> frame_;
  bool frame_unwritten_ = false;  // set_frame() since the last commit
  bool header_pending_ = false;   // a new log whose header did not fit yet
  std::string damage_;
};

}  // namespace semap::mapping
