#pragma once
// The records of an MCAP file (https://mcap.dev/spec, major version 0), as the writer writes
// them and the readers report them. Field names are the specification's.
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace semap::drivers::mcap {

// At the start and at the end of every file; the '0' is the major version.
inline constexpr std::array<std::uint8_t, 8> kMagic{0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};

enum class Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0a,
  kStatistics = 0x0b,
  kMetadata = 0x0c,
  kMetadataIndex = 0x0d,
  kSummaryOffset = 0x0e,
  kDataEnd = 0x0f,
};

// Every record is opcode u8 | content length u64 | content.
inline constexpr std::size_t kRecordHeadSize = 9;

using Bytes = std::vector<std::uint8_t>;
using StringMap = std::map<std::string, std::string>;
using ChannelCounts = std::map<std::uint16_t, std::uint64_t>;  // channel id -> count or offset

struct Header {
  std::string profile;
  std::string library;
};

struct Footer {
  std::uint64_t summary_start = 0;         // 0: no summary section
  std::uint64_t summary_offset_start = 0;  // 0: no summary offset section
  std::uint32_t summary_crc = 0;           // 0: not available
};

struct Schema {
  std::uint16_t id = 0;
  std::string name;
  std::string encoding;
  Bytes data;
};

struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;  // 0: no schema
  std::string topic;
  std::string message_encoding;
  StringMap metadata;
};

struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;
  std::uint64_t publish_time = 0;
  Bytes data;
};

// A chunk as the stream reader reports it: its fields without the records, which the reader
// reports one by one after it.
struct Chunk {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;  // 0: not checked
  std::string compression;             // "", "lz4" or "zstd"
  std::uint64_t compressed_size = 0;   // bytes of the records field
};

struct MessageIndex {
  std::uint16_t channel_id = 0;
  // (log_time, offset of the Message record in the chunk's uncompressed records)
  std::vector<std::pair<std::uint64_t, std::uint64_t>> records;
};

struct ChunkIndex {
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  std::uint64_t chunk_start_offset = 0;
  std::uint64_t chunk_length = 0;  // the whole Chunk record, opcode and length included
  ChannelCounts message_index_offsets;
  std::uint64_t message_index_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0;
  std::uint64_t uncompressed_size = 0;
};

struct Attachment {
  std::uint64_t log_time = 0;
  std::uint64_t create_time = 0;
  std::string name;
  std::string media_type;
  Bytes data;
  std::uint32_t crc = 0;  // of the fields before it; 0: not checked
};

struct AttachmentIndex {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  std::uint64_t log_time = 0;
  std::uint64_t create_time = 0;
  std::uint64_t data_size = 0;
  std::string name;
  std::string media_type;
};

struct Statistics {
  std::uint64_t message_count = 0;
  std::uint16_t schema_count = 0;
  std::uint32_t channel_count = 0;
  std::uint32_t attachment_count = 0;
  std::uint32_t metadata_count = 0;
  std::uint32_t chunk_count = 0;
  std::uint64_t message_start_time = 0;
  std::uint64_t message_end_time = 0;
  ChannelCounts channel_message_counts;
};

struct Metadata {
  std::string name;
  StringMap metadata;
};

struct MetadataIndex {
  std::uint64_t offset = 0;
  std::uint64_t length = 0;
  std::string name;
};

struct SummaryOffset {
  std::uint8_t group_opcode = 0;
  std::uint64_t group_start = 0;
  std::uint64_t group_length = 0;
};

struct DataEnd {
  std::uint32_t data_section_crc = 0;  // 0: not available
};

// A private (0x80-0xff) or future record: readers skip its content.
struct UnknownRecord {
  std::uint8_t opcode = 0;
  std::uint64_t length = 0;
};

using Record = std::variant<Header, Footer, Schema, Channel, Message, Chunk, MessageIndex,
                            ChunkIndex, Attachment, AttachmentIndex, Statistics, Metadata,
                            MetadataIndex, SummaryOffset, DataEnd, UnknownRecord>;

// The specification's name of a record type ("Header", "ChunkIndex", ...; "Unknown" for the
// opcodes it does not define). Record's alternatives are in opcode order.
const char* opcode_name(std::uint8_t opcode);
inline const char* record_name(const Record& record) {
  return opcode_name(static_cast<std::uint8_t>(record.index() + 1));
}

}  // namespace semap::drivers::mcap
