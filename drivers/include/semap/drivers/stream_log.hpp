#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <istream>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "semap/common/messages.hpp"
#include "semap/drivers/append_file.hpp"

namespace semap::drivers {

// The logs `semap-onboard --record` writes for the GNSS port's bytes and the camera frames, and
// its replay reads (docs/record-replay.md). A header, then records, all little-endian:
//   header        "SEMAPLOG" | kind u32 (1 bytes, 2 frames) | version u32 (1)
//   bytes record  stamp_ns i64 | length u32 | the bytes as read from the port
//   frame record  stamp_ns i64 | sequence u32 | fourcc u32 | width u32 | height u32 |
//                 stride u32 | length u32 | the frame's bytes as the driver delivered them
// Stamps are CLOCK_MONOTONIC nanoseconds: the read time of the bytes, the driver's frame stamp.
enum class StreamLogKind : std::uint32_t { kBytes = 1, kFrames = 2 };

inline constexpr std::uint32_t kStreamLogMaxChunk = 1u << 20;    // bytes of one read
inline constexpr std::uint32_t kStreamLogMaxFrame = 256u << 20;  // bytes of one frame
inline constexpr std::uint32_t kStreamLogMaxSide = 16384;        // pixels of a frame's side

struct ByteChunk {
  common::Stamp stamp;
  std::vector<std::uint8_t> bytes;
};

// Appends records to a new log (an existing file is replaced), through an AppendFile: a write
// that fails (disk full) is cut off so the log stays readable to its last whole record, its
// records are counted as lost, and writing is tried again a second later.
class StreamLogWriter {
 public:
  // Throws std::runtime_error naming the path when the file cannot be created.
  StreamLogWriter(const std::filesystem::path& path, StreamLogKind kind,
                  std::chrono::steady_clock::duration retry_after = std::chrono::seconds(1));

  // False when the record is lost (disk full, I/O error) or malformed (wrong kind, too long).
  bool write_bytes(common::Stamp stamp, std::span<const std::uint8_t> bytes);
  bool write_frame(const common::ImageFrame& frame);
  bool flush() { return file_.flush(); }

  bool ok() const { return !file_.failing(); }
  std::uint64_t records() const { return file_.records(); }  // taken and not lost
  std::uint64_t size() const { return file_.bytes(); }       // the same in bytes, with the header
  const AppendFile& file() const { return file_; }           // losses and the last error
  const std::filesystem::path& path() const { return file_.path(); }

 private:
  StreamLogKind kind_;
  AppendFile file_;
};

// Reads a log record by record. A damaged record (a length beyond the limits, an unknown pixel
// format, a record cut short as a crash mid-write leaves it) stops the reader; error() then
// names the log, the record and the field: "gnss.log: record 12 at byte 4096: length: ...".
class StreamLogReader {
 public:
  // The header is checked here: a wrong magic, kind or version leaves the reader failed.
  StreamLogReader(std::istream& in, std::string name, StreamLogKind kind);

  std::optional<ByteChunk> next_bytes();
  std::optional<common::ImageFrame> next_frame();

  // Empty while the log is intact.
  const std::string& error() const { return error_; }
  std::uint64_t records() const { return records_; }

 private:
  // Reads exactly `len` bytes; at the end of the log, false with no error when nothing of the
  // record was read yet (`first`), otherwise a "truncated" error naming `field`.
  bool read(void* out, std::size_t len, const char* field, bool first = false);
  void fail(const std::string& field, const std::string& what);

  std::istream& in_;
  std::string name_;
  StreamLogKind kind_;
  std::string error_;
  std::uint64_t records_ = 0;
  std::uint64_t offset_ = 0;        // bytes read so far
  std::uint64_t record_start_ = 0;  // where the record being read began
};

}  // namespace semap::drivers
