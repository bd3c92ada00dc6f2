#pragma once
// Writes an indexed, chunked MCAP file (docs/record-replay.md, "MCAP files"):
//   magic | Header | { Chunk | MessageIndex per channel }... | DataEnd |
//   Schemas | Channels | Statistics | ChunkIndexes | SummaryOffsets | Footer | magic
// Messages are gathered in a chunk with the Schema and Channel records they need (written into
// the chunk before the first message that uses them), compressed, and written when the chunk
// is full or spans `chunk_duration_ns` of log time. A crash loses the open chunk only; the
// file then reads up to its last whole chunk (McapMessageReader reports "truncated at byte N").
#include <cstdint>
#include <filesystem>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "semap/drivers/mcap_compression.hpp"
#include "semap/drivers/mcap_records.hpp"

namespace semap::drivers::mcap {

struct McapWriterOptions {
  std::string profile = "ros2";
  Compression compression = Compression::kZstd;
  int zstd_level = 1;  // zstd's fastest standard level: the robot's CPU goes to the pipeline
  // Uncompressed bytes at which a chunk is written. 1 MiB gives zstd enough context for a good
  // ratio, keeps a reader's memory per chunk small, and at a few MB/s of sensor data is well
  // under a second of recording.
  std::uint64_t chunk_size = 1u << 20;
  // A chunk is also written once its messages span this much log time (0: no limit), so a
  // slow stream reaches the disk within that time. The recorder should call flush() when no
  // message arrives for a while: this check runs only when a message is written.
  std::uint64_t chunk_duration_ns = 1'000'000'000;
  // fdatasync after each chunk: the chunk then survives a power loss, not only a crash of the
  // process. Costs a disk flush per chunk (milliseconds on eMMC).
  bool sync_each_chunk = false;
};

// A write that failed: names the file and the call, keeps errno.
class McapWriteError : public std::runtime_error {
 public:
  McapWriteError(const std::string& what, int error) : std::runtime_error(what), error_(error) {}
  int error() const { return error_; }

 private:
  int error_;
};

// One writer per file and not thread-safe: the caller serialises all calls (the recorder's
// single writer thread). Writes go straight to the file descriptor (pwrite), one chunk and its
// indexes at a time. A chunk that cannot be written whole (ENOSPC, EFBIG, EIO) is cut off
// again (ftruncate), so the file keeps ending after the last whole chunk; write() or flush()
// throws McapWriteError ("<path>: write: <strerror>"), the chunk's messages are counted in
// messages_lost(), and the writer stays usable: the next chunk tries again and repeats the
// Schema and Channel records the lost chunk held.
class McapWriter {
 public:
  // Creates or replaces `path` and writes the magic and the Header (library "semap <version>").
  // Throws McapWriteError when the file cannot be created or written.
  explicit McapWriter(std::filesystem::path path, McapWriterOptions options = {});
  // Closes the file if close() was not called; errors are then lost (call close() to see them).
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  // Ids count from 1. Throws std::length_error past 65535 schemas or channels, and
  // std::invalid_argument for a channel of an unknown schema (0 is "no schema").
  std::uint16_t add_schema(std::string name, std::string encoding,
                           std::span<const std::uint8_t> data);
  std::uint16_t add_schema(std::string name, std::string encoding, std::string_view text) {
    return add_schema(std::move(name), std::move(encoding),
                      {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()});
  }
  std::uint16_t add_channel(std::uint16_t schema_id, std::string topic,
                            std::string message_encoding, StringMap metadata = {});

  // Adds a message to the open chunk; writes the chunk when it is full or spans
  // chunk_duration_ns. Throws std::invalid_argument for an unknown channel, McapWriteError
  // when the chunk could not be written (see above).
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
             std::uint64_t publish_time_ns, std::span<const std::uint8_t> data);
  // Writes the open chunk now (nothing when it is empty).
  void flush();
  // Writes the open chunk (and every channel not yet written), DataEnd, the summary, the
  // summary offsets, the Footer and the closing magic. Throws McapWriteError; the file then
  // ends after its last whole chunk. Later calls do nothing.
  void close();

  const std::filesystem::path& path() const { return path_; }
  std::uint64_t messages_written() const { return stats_.message_count; }  // in the file
  std::uint64_t messages_lost() const { return messages_lost_; }           // in chunks that failed
  std::uint64_t file_size() const { return file_size_; }

 private:
  void ensure_channel_in_chunk(std::uint16_t channel_id);
  void write_chunk();
  // Appends `bytes` at the end of the file or cuts it back and throws.
  void append(std::span<const std::uint8_t> bytes);
  void write_summary_and_footer();

  std::filesystem::path path_;
  McapWriterOptions options_;
  int fd_ = -1;
  bool closed_ = false;
  std::uint64_t file_size_ = 0;
  std::uint32_t data_crc_ = 0;  // of every byte in the file so far (the data section's CRC)

  std::vector<Schema> schemas_;    // id - 1
  std::vector<Channel> channels_;  // id - 1
  // In the file already / in the open chunk only (they join the file when it is written).
  std::set<std::uint16_t> file_schemas_, file_channels_;
  std::set<std::uint16_t> chunk_schemas_, chunk_channels_;

  // The open chunk: its uncompressed records, time range and message indexes (in the order
  // channels first appear in it).
  Bytes chunk_records_;
  std::uint64_t chunk_messages_ = 0;
  std::uint64_t chunk_start_time_ = 0;
  std::uint64_t chunk_end_time_ = 0;
  std::vector<MessageIndex> chunk_indexes_;

  Statistics stats_;
  std::vector<ChunkIndex> chunk_index_;
  std::uint64_t messages_lost_ = 0;
  Bytes compressed_;  // reused: the open chunk's records compressed
  Bytes scratch_;     // reused: the Chunk record and its MessageIndex records
};

}  // namespace semap::drivers::mcap
