#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <istream>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "semap/common/messages.hpp"

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

// Appends records to a new log (an existing file is replaced). Writes go through stdio's
// buffer; a failed write is remembered, and later writes are refused.
class StreamLogWriter {
 public:
  // Throws std::runtime_error naming the path when the file cannot be created.
  StreamLogWriter(const std::filesystem::path& path, StreamLogKind kind);
  ~StreamLogWriter();
  StreamLogWriter(const StreamLogWriter&) = delete;
  StreamLogWriter& operator=(const StreamLogWriter&) = delete;

  // False once a write failed (disk full, I/O error).
  bool write_bytes(common::Stamp stamp, std::span<const std::uint8_t> bytes);
  bool write_frame(const common::ImageFrame& frame);
  bool flush();

  bool ok() const { return ok_; }
  std::uint64_t records() const { return records_; }
  std::uint64_t size() const { return size_; }  // bytes written, header included
  const std::filesystem::path& path() const { return path_; }

 private:
  bool put(const void* data, std::size_t len);

  std::filesystem::path path_;
  StreamLogKind kind_;
  std::FILE* file_ = nullptr;
  bool ok_ = true;
  std::uint64_t records_ = 0;
  std::uint64_t size_ = 0;
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
