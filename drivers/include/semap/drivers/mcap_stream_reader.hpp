#pragma once
// Walks an MCAP file from its first byte to its last and reports every record in file order:
// a Chunk is reported, then the records it holds (decompressed), then what follows it. CRCs
// that are present (not 0) are checked: chunk records, attachments, the data section at
// DataEnd and the summary at the Footer.
//
// Bad bytes never throw and never crash: next() returns nothing and status() says why, with
// error() naming the file, the byte, the record and the field:
//   "run.mcap: byte 4096: Chunk.uncompressed_crc: 0x1234abcd, records give 0x0badf00d".
// A file that simply ends early (a crash while recording) is kTruncated, not kError:
//   "run.mcap: truncated at byte 1048576: Chunk record needs 1001234 bytes, 52 left".
// Allocations are bounded by the file's size, and a chunk's by max_chunk_size.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>

#include "semap/drivers/mcap_records.hpp"

namespace semap::drivers::mcap {

struct McapReaderOptions {
  bool validate_crcs = true;
  // Largest uncompressed chunk accepted (its records are held in memory while read).
  std::uint64_t max_chunk_size = 256u << 20;
};

enum class McapReadStatus {
  kReading,    // next() may give more records
  kEnd,        // the closing magic was read
  kTruncated,  // the file ends before its Footer and closing magic
  kError,      // damaged bytes (error() says where)
};

class McapStreamReader {
 public:
  // Reads `bytes`, which must outlive the reader; `name` prefixes errors.
  McapStreamReader(std::span<const std::uint8_t> bytes, std::string name,
                   McapReaderOptions options = {});
  // Reads the file with pread, one record at a time; a file that cannot be opened leaves the
  // reader in kError.
  explicit McapStreamReader(const std::filesystem::path& path, McapReaderOptions options = {});
  ~McapStreamReader();
  McapStreamReader(const McapStreamReader&) = delete;
  McapStreamReader& operator=(const McapStreamReader&) = delete;

  // The next record, or nothing at the end or on damage (status() tells which).
  std::optional<Record> next();

  const std::string& name() const { return name_; }  // the path, or the name given
  McapReadStatus status() const { return status_; }
  const std::string& error() const { return error_; }  // empty while reading and at the end
  // Where a truncated file ends its last whole record: everything before it was reported.
  std::uint64_t truncated_at() const { return truncated_at_; }
  // The record next() returned last: its byte in the file, or for a record in a chunk, its
  // chunk's byte and its own byte in the chunk's uncompressed records.
  std::uint64_t record_offset() const { return record_offset_; }
  bool in_chunk() const { return in_chunk_; }
  std::uint64_t offset_in_chunk() const { return offset_in_chunk_; }

 private:
  std::optional<Record> next_in_chunk();
  std::optional<Record> next_top_level();
  Record read_chunk(std::span<const std::uint8_t> content);
  void check_footer(const Footer& footer);
  // Reads [at, at + n) of the source into `out`; false on an I/O error (then failed).
  bool read(std::uint64_t at, std::size_t n, std::uint8_t* out);
  void fail(std::uint64_t at, const std::string& what);
  void truncate(std::uint64_t at, const std::string& what);

  std::string name_;
  McapReaderOptions options_;
  std::span<const std::uint8_t> bytes_;  // the source when it is a span
  int fd_ = -1;                          // the source when it is a file
  std::uint64_t size_ = 0;

  McapReadStatus status_ = McapReadStatus::kReading;
  std::string error_;
  std::uint64_t truncated_at_ = 0;
  std::uint64_t offset_ = 0;  // next top-level record
  std::uint64_t record_offset_ = 0;
  bool in_chunk_ = false;
  std::uint64_t offset_in_chunk_ = 0;
  bool started_ = false;        // magic and Header read
  bool data_ended_ = false;     // DataEnd read: the summary follows
  std::uint32_t data_crc_ = 0;  // of every top-level byte before DataEnd

  Bytes content_;             // the current top-level record's content
  Bytes chunk_records_;       // the current chunk's records, uncompressed
  std::size_t chunk_at_ = 0;  // next record in chunk_records_
  std::uint64_t chunk_offset_ = 0;
};

}  // namespace semap::drivers::mcap
